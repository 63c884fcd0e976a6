"""The waves' horizontal pull on a hull: the Froude-Krylov force and its added-mass share.

Why: buoyancy pushes straight up, so a hull in a wave moved sideways only as far as the
damping dragged it: a third as far as the water it floats in (a naval architect's check in a
regular 2.55 s wave; 0.5-0.7 in the `medium` preset). In linear deep-water waves the water at
the surface accelerates at -g grad(eta), so the undisturbed pressure pushes a floating hull
(displaced mass m) with -m g grad(eta), and its added mass A takes the same share (Morison):
F = -(m + A) g <grad(eta)>, horizontal: m's share at the centre of buoyancy, A's at the
origin, where the model's added mass acts (`wave_pull`).

<grad(eta)> is the slope of the plane fitted, by least squares weighted by waterplane area,
to the surface at the hull's buoyancy columns, which the buoyancy samples anyway: for waves
long against the hull it is the slope at the hull, and for short ones it averages out as
the pressure over the hull does (taking the water's acceleration at the origin instead drove
a monohull at 0.49 m/s surfing 10 m waves). The decay with depth is left out (the hulls'
drafts are small against the waves that move them).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from catabot.config.vessel import VesselModel
from catabot.world import rotations
from services.physics import kernels
from services.physics.hydro import Array, Columns
from services.physics.kernels import jit


@jit
def surface_slopes(rot: Array, bottom: Array, area: Array, eta: Array) -> Array:
    """(N, 3) each hull's fitted surface slope (d eta/dx, d eta/dy, 0), world frame, from
    the heights `eta` (N, C) at its columns (bottom (N, 3, C), body frame; area (N, C), 0 for
    padding); zero where the columns, seen from above, lie on a line (a hull on its side).
    Compiled: as NumPy passes over (N, C) it cost the medium swell 0.08 ms a step."""
    n, c = area.shape
    out = np.zeros((n, 3))
    x, y = np.empty(c), np.empty(c)
    for i in range(n):
        r, sw, sx, sy, se = rot[i], 0.0, 0.0, 0.0, 0.0
        for k in range(c):
            b0, b1, b2 = bottom[i, 0, k], bottom[i, 1, k], bottom[i, 2, k]
            x[k] = r[0, 0] * b0 + r[0, 1] * b1 + r[0, 2] * b2
            y[k] = r[1, 0] * b0 + r[1, 1] * b1 + r[1, 2] * b2
            w = area[i, k]
            sw, sx, sy, se = sw + w, sx + w * x[k], sy + w * y[k], se + w * eta[i, k]
        if sw <= 0.0:
            continue
        mx, my, me = sx / sw, sy / sw, se / sw
        sxx, syy, sxy, sxe, sye = 0.0, 0.0, 0.0, 0.0, 0.0
        for k in range(c):
            w, dx, dy, de = area[i, k], x[k] - mx, y[k] - my, eta[i, k] - me
            sxx, syy, sxy = sxx + w * dx * dx, syy + w * dy * dy, sxy + w * dx * dy
            sxe, sye = sxe + w * dx * de, sye + w * dy * de
        det = sxx * syy - sxy * sxy
        if det > 1e-9 * (sxx + syy) ** 2 + 1e-30:
            out[i, 0] = (syy * sxe - sxy * sye) / det
            out[i, 1] = (sxx * sye - sxy * sxe) / det
    return out


@dataclass(frozen=True)
class PullTable:
    """Per hull: what the waves pull, the displaced mass m (N,) at its centre of buoyancy at
    rest `at` (N, 3, body frame), and the added masses (A11, A22, A33) (N, 3) at the origin."""

    mass: Array
    at: Array
    added: Array

    @classmethod
    def of(cls, models: Sequence[VesselModel], cols: Columns) -> PullTable:
        mass = np.array([m.mass_kg for m in models], dtype=np.float64)
        added = np.array([m.added_mass[:3] for m in models], dtype=np.float64).reshape(-1, 3)
        return cls(mass, centres_of_buoyancy(cols), added)

    def take(self, rows: NDArray[np.intp]) -> PullTable:
        return PullTable(self.mass[rows], self.at[rows], self.added[rows])


def wave_pull(
    table: PullTable, cols: Columns, rot: Array, eta: Array, *, gravity: float,
    wet: Array | None,
) -> Array:  # fmt: skip
    """Body-frame wrench (N, 6) about the origin: the water's acceleration -g <grad(eta)>
    times the displaced mass at each hull's centre of buoyancy (the undisturbed pressure's
    push), plus times the added masses at the origin, scaled by its wetness (None: all wet).
    The added-mass share acts where the model's added mass is (a diagonal matrix about the
    origin), so that it cancels its own reaction as the hull moves with the water: put at the
    centre of buoyancy, 0.08 m under the buoy's origin, it tilted the buoy against the wave
    slope (a third of the slope's pitch in a 6 s wave); all of it at the origin heeled a
    buoyed mark off the surface normal, its ballast below."""
    slopes = surface_slopes(rot, cols.bottom_m, cols.area_m2, np.ascontiguousarray(eta))
    accel = kernels.to_body(rot, -gravity * slopes)
    out = np.zeros((len(rot), 6))
    push = table.mass[:, None] * accel
    out[:, :3] = push + table.added * accel
    out[:, 3:] = rotations.cross(table.at, push)
    if wet is not None:
        out *= wet[:, None]
    return out


def centres_of_buoyancy(cols: Columns) -> Array:
    """(N, 3) body frame: each hull's centre of buoyancy floating level at its waterline
    (z = 0 at the origin): its waterplane's centroid, half way down to the mean keel."""
    w = cols.area_m2 / np.maximum(cols.area_m2.sum(axis=1, keepdims=True), 1e-12)
    out = np.einsum("nc,nkc->nk", w, cols.bottom_m)
    out[:, 2] = np.minimum(out[:, 2], 0.0) / 2.0
    return out


def warm_up() -> None:
    """Load the kernel now (kernels.warm_up says why)."""
    surface_slopes(np.eye(3)[None], np.zeros((1, 3, 1)), np.ones((1, 1)), np.zeros((1, 1)))
