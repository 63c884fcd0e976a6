"""LiDAR in rain: the CataBotSim paper's model (§III-B.2.a, equations (1)-(7)), all beams at once.

Read next to the paper. Per beam, with Z the raycast distance (or the maximum range when the
beam hit nothing):

  step one   N(D) = 8000 exp(-4.1 R^-0.21 D)                          (1)  drops per m^3
             mu = pi r^2 Z N(D)                                        (2)  mean drops in the beam
             n ~ Poisson(mu)                                           (3)
  step two   P(Z) = rho / Z^2 exp(-2 alpha Z)                          (4)  relative power
             RIO:  rho = s / pi                                        (5)
                   alpha = n Q_ext (pi D^2 / 4) / (pi r^2 Z)           (6)
             RIRD: alpha = 0 (no drop before the first one), Z = Z_d the distance to the first
                   drop (the least of n uniform distances in (0, Z]), and rho the drops'
                   backscatter n Q_back (pi D^2 / 4) / (pi r^2 Z_d)    (7)
  step three object hit and n = 0            -> the object
             RIO >= RIRD (object hit)         -> the object if RIO > threshold, else nothing
             RIRD > RIO, or no object         -> the drop if RIRD > threshold, else nothing

Units: D is in millimetres in the empirical law (1), as the paper and its sources give it, and
in metres in the cross-section pi D^2 / 4 of (6)-(7), so alpha is in 1/m and exp(-2 alpha Z) is
dimensionless. (The original code used millimetres there too, which makes any drop in the beam
hide the object; the paper's Fig. 5 shows objects seen through rain.)

Randomness: one Poisson draw per beam, then one uniform per beam, for every beam whatever
its n: the same scan from the same seeded generator gives the same bytes. NumPy's Poisson
sampler consumes a varying amount of the stream per draw, so a change in one beam's range
shifts the draws of the beams after it (the statistics are unchanged).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from catabot.errors import CataBotError

F64 = NDArray[np.float64]


class RainModelError(CataBotError, ValueError):
    """Rain-model parameters or inputs outside their meaningful range."""


@dataclass(frozen=True)
class RainParams:
    """The model's constants (paper defaults; the original code's D was 2.75 mm)."""

    drop_diameter_mm: float = 3.25
    beam_radius_m: float = 0.02
    detection_threshold: float = 5e-6
    reflectivity: float = 0.9  # s in (5): rho = s / pi
    q_ext: float = 2.0
    q_back: float = 2.0

    def __post_init__(self) -> None:
        for name in ("drop_diameter_mm", "beam_radius_m", "detection_threshold", "reflectivity"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0):
                raise RainModelError(f"rain parameter {name} must be > 0 (got {value!r})")
        for name in ("q_ext", "q_back"):
            if not (math.isfinite(getattr(self, name)) and getattr(self, name) >= 0):
                raise RainModelError(f"rain parameter {name} must be >= 0")


@dataclass
class RainReturns:
    """What the LiDAR reports per beam after rain: range (inf: no return), relative power
    of the return (eq. 4; 0 with none), and whether the return is a raindrop."""

    range: F64
    intensity: F64
    is_rain: NDArray[np.bool_]


def drop_density(rate_mm_h: float, drop_diameter_mm: float) -> float:
    """N(D), eq. (1): mean number of drops per cubic metre at rain rate R (mm/h)."""
    if not (math.isfinite(rate_mm_h) and rate_mm_h >= 0):
        raise RainModelError(f"rain rate must be a finite number >= 0 mm/h (got {rate_mm_h!r})")
    if rate_mm_h == 0:
        return 0.0  # R^-0.21 -> inf: no drops
    return 8000.0 * math.exp(-4.1 * rate_mm_h**-0.21 * drop_diameter_mm)


def mean_drops(rate_mm_h: float, distance_m: F64 | float, p: RainParams) -> F64:
    """mu, eq. (2): mean number of drops in a beam of radius r and length Z."""
    return np.asarray(
        math.pi
        * p.beam_radius_m**2
        * np.asarray(distance_m)
        * drop_density(rate_mm_h, p.drop_diameter_mm)
    )


def apply_rain(
    distance: F64,
    max_range: float,
    rate_mm_h: float,
    p: RainParams,
    rng: np.random.Generator,
    *,
    rho: F64 | None = None,
    gated: bool = False,
) -> RainReturns:
    """Steps one to three for every beam; `distance` is the raycast range (inf: no hit).
    `rho`: each beam's object backscatter (default (5) for every surface, the paper's);
    `gated`: every return must pass the detection threshold, not only one through rain (a
    receiver does not see a surface too dim for it because the air is dry)."""
    hit = np.isfinite(distance) & (distance <= max_range)
    z = np.where(hit, distance, max_range)  # Z: to the object, or the whole beam
    z = np.maximum(z, 1e-6)  # a beam starting on a surface still has a length
    rho_obj = p.reflectivity / math.pi if rho is None else rho  # (5)
    area = math.pi * (p.drop_diameter_mm * 1e-3) ** 2 / 4.0  # drop cross-section, m^2
    beam = math.pi * p.beam_radius_m**2  # beam cross-section, m^2
    # step one
    n = rng.poisson(mean_drops(rate_mm_h, z, p)).astype(np.float64)  # (2), (3)
    u = rng.random(z.shape)
    z_drop = z.copy()  # least of n uniforms in (0, Z]; n = 0: Z (what u ** inf gives)
    some = np.flatnonzero(n > 0)  # the power, the costliest step, only where it matters
    z_drop[some] = z[some] * (1.0 - u[some] ** (1.0 / n[some]))
    np.maximum(z_drop, 1e-6, out=z_drop)
    # step two
    alpha_obj = n * p.q_ext * area / (beam * z)  # (6)
    rio = np.where(hit, rho_obj / z**2 * np.exp(-2.0 * alpha_obj * z), 0.0)  # (4)
    rho_drop = n * p.q_back * area / (beam * z_drop)  # (7)
    rird = np.where(n > 0, rho_drop / z_drop**2, 0.0)  # (4) with alpha = 0
    # step three
    thr = p.detection_threshold
    object_wins = hit & ((n == 0) | (rio >= rird))
    show_object = object_wins & (((n == 0) & (not gated)) | (rio > thr))
    show_drop = ~object_wins & (rird > thr)
    out_range, intensity = np.full(z.shape, np.inf), np.zeros(z.shape)
    for out, obj, drop in ((out_range, z, z_drop), (intensity, rio, rird)):
        np.copyto(out, obj, where=show_object)  # show_object and show_drop never overlap
        np.copyto(out, drop, where=show_drop)
    return RainReturns(out_range, intensity, show_drop)
