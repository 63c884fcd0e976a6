"""The waves' orbital velocity averaged over each hull's waterplane: what damping and added
mass take as the water's velocity (forces.py, sea.py).

Why: they took it at the body origin, so in waves about as long as the hull the whole hull
was damped against the flow of one point, in step with its own heave and pitch. The rectified
products pushed a free hull downwave: the bundled monohull drifted at 0.77 m/s in a regular
2 s wave 0.25 m high (Stokes drift there 0.03 m/s; a naval architect's check), 0.13 m/s in a
3 s one. Averaged over the waterplane (the pressure acts on the whole hull, as wave_pull.py's
fitted slope already has it), the short components largely cancel along the hull: 0.22 and
-0.01 m/s (the catamaran 0.08 -> -0.03 m/s at 2 s), and a hull short against the waves sees
the origin's velocity as before.

Per wave component j the waterplane average of cos(k_j . x + c) about the origin is
Re(F_j e^(i c)), F_j = sum_c w_c exp(i k_j . r_c) over the hull's buoyancy columns (plan view
in the body frame, weights their areas). F_j depends on the hull's heading alone (the wave
vector seen in the body frame), so it is tabulated per column layout at BINS headings when
the sea is set, and each step takes one gather and four products per body and component.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from catabot.world.waves import WaveField
from services.physics.hydro import Array

F32 = NDArray[np.float32]
BINS = 512  # headings tabulated: 0.7 deg apart, a phase error k r 0.006 at most (0.02 rad
# for a 3 m half-hull in a 1 rad/m wave)


class HullAverage:
    """Per column layout, F_j at BINS headings; per step, the phases' cosines and sines
    turned into their waterplane averages."""

    def __init__(self, bottom_m: Array, area_m2: Array) -> None:
        """bottom_m (N, C, 3) body-frame column bottoms, area_m2 (N, C) (0: padding)."""
        keys: dict[bytes, int] = {}
        self.layout_of = np.array(
            [keys.setdefault(b.tobytes() + a.tobytes(), len(keys)) for b, a in
             zip(bottom_m, area_m2, strict=True)], dtype=np.intp,
        )  # fmt: skip
        first = [int(np.flatnonzero(self.layout_of == k)[0]) for k in range(len(keys))]
        weights = area_m2[first] / np.maximum(area_m2[first].sum(axis=1, keepdims=True), 1e-12)
        self._plan = bottom_m[first][:, :, :2]  # (L, C, 2)
        self._weights = weights  # (L, C)
        self._re: F32 | None = None
        self._im: F32 | None = None
        self._tables: dict[bytes, tuple[F32, F32]] = {}  # the last three seas' (use)

    def use(self, waves: WaveField) -> None:
        """The factors of a sea's components (at the start and at a change of the waves).
        They depend on the components' wave vectors alone, not their amplitudes, so the 40
        stages of a change of sea (sea_change.py: the same components, rescaled) share one
        table: built at every stage, 0.1 s each, a paced run fell behind for 10 s."""
        key = waves.wavenumbers_radpm.tobytes() + waves.directions_rad.tobytes()
        if key not in self._tables:
            self._tables = {**dict(list(self._tables.items())[-2:]), key: self._build(waves)}
        self._re, self._im = self._tables[key]

    def _build(self, waves: WaveField) -> tuple[F32, F32]:
        heading = np.arange(BINS) * (2.0 * math.pi / BINS)
        turned = waves.directions_rad[None, :] - heading[:, None]  # (B, M)
        k = waves.wavenumbers_radpm[None, :]
        kx, ky = k * np.cos(turned), k * np.sin(turned)  # the wave vectors in the body frame
        factor = np.empty((len(self._plan), BINS, kx.shape[1]), np.complex128)
        for layout, (plan, w) in enumerate(zip(self._plan, self._weights, strict=True)):
            real = w > 0  # padding columns weigh nothing
            factor[layout] = _factor(plan[real], w[real], kx, ky)
        return factor.real.astype(np.float32), factor.imag.astype(np.float32)

    def average(self, cos: F32, sin: F32, rot: Array) -> tuple[F32, F32]:
        """The waterplane averages of cos and sin of each body's phases (N, M), given the
        phases' cosines and sines at the origins and the bodies' rotations (N, 3, 3)."""
        assert self._re is not None and self._im is not None, "use(waves) first"
        yaw = np.arctan2(rot[:, 1, 0], rot[:, 0, 0])
        at = np.rint(yaw * (BINS / (2.0 * math.pi))).astype(np.intp) % BINS
        re, im = self._re[self.layout_of, at], self._im[self.layout_of, at]
        return re * cos - im * sin, im * cos + re * sin


def _factor(plan: Array, w: Array, kx: Array, ky: Array) -> NDArray[np.complex128]:
    """sum_c w_c exp(i (kx x_c + ky y_c)) for every (heading, component) of kx, ky (B, M).
    Hull columns stand on a grid (16-32 stations along, 4-20 across), so the sum splits
    into a few exponentials per station and a small matmul (a WAM-V's 320 columns: 0.4 s
    at every change of sea as one exponential per column); any other layout takes one
    exponential per column."""
    xs, ix = np.unique(plan[:, 0].round(9), return_inverse=True)
    ys, iy = np.unique(plan[:, 1].round(9), return_inverse=True)
    if len(xs) * len(ys) > 4 * len(w):
        return np.exp(1j * (kx[..., None] * plan[:, 0] + ky[..., None] * plan[:, 1])) @ w
    grid = np.zeros((len(xs), len(ys)))
    np.add.at(grid, (ix, iy), w)
    along = np.exp(1j * kx[..., None] * xs) @ grid  # (B, M, ny)
    return np.einsum("bmy,bmy->bm", along, np.exp(1j * ky[..., None] * ys))
