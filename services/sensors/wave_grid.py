"""The wave surface sampled once per cast on a grid, with a proven bound on its error.

Why: evaluating eta = sum_m a_m cos(k_m . x - w_m t + phi_m) costs one float32 cosine per
component (48 by default) per ray and per step of a root search; a ray-cast sensor takes
~7 steps per ray (services/sensors/water.py's exact march). On a regular grid the same sum
separates: cos(A_i + B_j) = cos A_i cos B_j - sin A_i sin B_j with A = k_u u + p, B = k_v v,
so every node's height and gradient is one float32 matmul (nx, 2M) @ (2M, 3 ny) with only
M (nx + ny) sines and cosines. 30 k nodes cost ~0.25 ms; a ray then costs a gather and a few
multiply-adds per cell it visits (services/sensors/wave_kernel.py).

Error bound. Between nodes the surface is the bilinear interpolant of the node heights.
For a tensor-product linear interpolant |g - eta| <= hu^2/8 max|eta_uu| + hv^2/8 max|eta_vv|
(one 1D bound per axis; the second interpolation is a convex combination), and
|eta_uu| <= sum a k_u^2 (every component at its crest at once). The grid axes are the
principal axes of S = sum a k k^T (the spectrum's curvature tensor), and the cell sizes
split the tolerance between them, hu = sqrt(4 eps / S_uu), hv = sqrt(4 eps / S_vv), which
minimises the nodes for a given bound: the medium preset (S_uu 0.033, S_vv 0.003 1/m) gets
0.92 x 3.3 m cells for eps = 7 mm, 45% fewer nodes than square ones. Gradients (normals)
are the bilinear interpolants of the exact node gradients: their error is bounded the same
way by the third moments of the spectrum (GridSpec.grad_err, ~5e-4 for the medium sea).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from catabot.world.waves import WaveField
from services.sensors.wave_bounds import NODE, bounds

F32 = NDArray[np.float32]
F64 = NDArray[np.float64]
EPS_M = 0.007  # bound on |bilinear - eta| a grid is built for (hits are roots of the bilinear)
MAX_ASPECT = 16.0  # hv <= 16 hu: a long-crested sea (S_vv ~ 0) still gets a few rows
BLOCK_CELLS = 4  # side of the blocks whose highest node a ray passes over whole
TWO_PI = 2.0 * math.pi


@dataclass(frozen=True)
class GridSpec:
    """What a grid needs of one WaveField, computed once per sea: its frame and cell sizes."""

    rot: F64  # (2, 2) world xy -> grid uv (rows: the u and v axes)
    k_u: F64  # (M,) wavenumber components along u and v
    k_v: F64
    hu: float  # cell sizes (m)
    hv: float
    eps: float  # proven |bilinear - eta| bound at these sizes (m)
    curvature: F64  # (2, 2) sum a k k^T in the world frame: |d2 eta/ds2| <= d^T S d along d
    grad_err: tuple[float, float]  # bounds on the error of the interpolated d eta/du, d eta/dv


def grid_spec(waves: WaveField, eps: float = EPS_M) -> GridSpec | None:
    """The grid frame and cell sizes for `waves` (None for calm water: nothing to sample)."""
    a = waves.amplitudes_m
    if waves.is_calm or not np.any(a > 0.0):
        return None
    k, theta = waves.wavenumbers_radpm, waves.directions_rad
    kxy = np.stack([k * np.cos(theta), k * np.sin(theta)])  # (2, M)
    s = (kxy * a) @ kxy.T
    _, vec = np.linalg.eigh(s)
    ang = math.atan2(vec[1, 1], vec[0, 1])  # the axis of largest curvature becomes u
    rot = np.array([[math.cos(ang), math.sin(ang)], [-math.sin(ang), math.cos(ang)]])
    k_u, k_v = rot @ kxy
    s_uu, s_vv = float(np.sum(a * k_u**2)), float(np.sum(a * k_v**2))
    hu = math.sqrt(4.0 * eps / s_uu)
    hv = min(math.sqrt(4.0 * eps / s_vv), MAX_ASPECT * hu) if s_vv > 0.0 else MAX_ASPECT * hu
    au, av = np.abs(k_u), np.abs(k_v)
    grad_err = (
        float(hu**2 / 8 * np.sum(a * au**3) + hv**2 / 8 * np.sum(a * au * av**2)),
        float(hu**2 / 8 * np.sum(a * av * au**2) + hv**2 / 8 * np.sum(a * av**3)),
    )
    bound = hu**2 / 8 * s_uu + hv**2 / 8 * s_vv
    return GridSpec(rot, k_u, k_v, hu, hv, bound, s, grad_err)


class Scratch:
    """Arrays kept between casts: a fresh array of a few hundred kB costs a page fault per
    4 kB page when first written (~2.5 us each on the reference VM: 4.7 ms for the
    temporaries of one step over 120 k rays), reused memory costs nothing."""

    def __init__(self) -> None:
        self._bufs: dict[str, np.ndarray] = {}
        self.across: tuple[tuple[int, int], F32] | None = None  # WaveGrid._across, kept

    def get(self, name: str, shape: tuple[int, ...], dtype: type = np.float32) -> np.ndarray:
        size = math.prod(shape)
        buf = self._bufs.get(name)
        if buf is None or buf.size < size or buf.dtype != dtype:
            buf = self._bufs[name] = np.empty(max(size, 1024), dtype=dtype)
        return buf[:size].reshape(shape)


class WaveGrid:
    """The surface's nodes over the box lo..hi (grid frame, metres from `anchor`) at one
    instant, with the bounds a ray search needs: extremes, steepest rises and each block's
    highest node. Positions are in cell units, f = (uv - uv0) / (hu, hv); node (i, j) is
    flat[NODE (i nv + j)], its d/du and d/dv the next two."""

    def __init__(
        self,
        spec: GridSpec,
        waves: WaveField,
        time_s: float,
        anchor: F64,
        box: tuple[F64, F64],
        scratch: Scratch,
    ) -> None:
        lo, hi = box
        self.spec, self.anchor = spec, anchor
        self.hu, self.hv = spec.hu, spec.hv
        # nodes on the lattice of the cell sizes about the anchor, a cell of margin beyond
        # the box: a sensor's next cast then has the same v-nodes, and `_across` is kept
        self.j0 = math.floor(lo[1] / spec.hv) - 1
        self.u0, self.v0 = (math.floor(lo[0] / spec.hu) - 1) * spec.hu, self.j0 * spec.hv
        self.nu = math.ceil((hi[0] - self.u0) / spec.hu) + 2
        self.nv = math.ceil((hi[1] - self.v0) / spec.hv) + 2
        self.flat = self._nodes(waves, time_s, scratch)
        helpers = bounds()
        low, high, rise_u, rise_v = helpers.surface_bounds(self.flat, (self.nu, self.nv))
        self.zmin, self.zmax = float(low), float(high)
        self.rise = (float(rise_u), float(rise_v))  # steepest rise per cell along u, v
        top = helpers.block_tops(self.flat, (self.nu, self.nv), BLOCK_CELLS)
        self.blocks = (top, top.shape, BLOCK_CELLS)

    def _nodes(self, waves: WaveField, time_s: float, scratch: Scratch) -> F32:
        """Height, d/du and d/dv of every node, flat, node after node (row i: the nv nodes of
        u-node i). M (nu + nv) trig calls and one matmul; a ray step gathers its cell's four
        corners straight from it."""
        spec, m = self.spec, waves.amplitudes_m.size
        k, theta = waves.wavenumbers_radpm, waves.directions_rad
        shift = (
            k * (np.cos(theta) * self.anchor[0] + np.sin(theta) * self.anchor[1])
            + waves.phases_rad
            - waves.frequencies_radps * time_s
        )
        cos_a, sin_a = _trig(np.outer(self.u0 + spec.hu * np.arange(self.nu), spec.k_u) + shift)
        left = scratch.get("grid_left", (self.nu, 2 * m))
        left[:, :m], left[:, m:] = cos_a, sin_a
        out = scratch.get("grid_nodes", (self.nu, NODE * self.nv))
        np.matmul(left, self._across(waves, scratch), out=out)
        return out.ravel()

    def _across(self, waves: WaveField, scratch: Scratch) -> F32:
        """The (2M, NODE nv) right factor: B = k_v v holds neither the time nor the anchor, so a
        grid with the same v-nodes as the last one reuses it (a LiDAR's scans: ~0.04 ms)."""
        key = (self.j0, self.nv)
        if scratch.across is not None and scratch.across[0] == key:
            return scratch.across[1]
        spec, m = self.spec, waves.amplitudes_m.size
        cos_b, sin_b = _trig(np.outer(self.v0 + spec.hv * np.arange(self.nv), spec.k_v))
        a = waves.amplitudes_m.astype(np.float32)
        right = np.empty((2 * m, self.nv, NODE), np.float32)
        right[:m, :, 0], right[m:, :, 0] = (a * cos_b).T, (-a * sin_b).T  # cos(A + B)
        for field, k_axis in ((1, spec.k_u), (2, spec.k_v)):  # d/du: -k_u sin(A + B)
            ak = (a * k_axis).astype(np.float32)
            right[:m, :, field], right[m:, :, field] = (-ak * sin_b).T, (-ak * cos_b).T
        scratch.across = key, right.reshape(2 * m, -1)
        return scratch.across[1]


def _trig(phase: F64) -> tuple[F32, F32]:
    """cos and sin of float64 phases: reduced to one turn in float64, then float32 (float64
    trig costs ~10x; the reduction keeps float32 at its rounding, ~1e-7 of an amplitude)."""
    phase -= TWO_PI * np.rint(phase / TWO_PI)
    p32 = phase.astype(np.float32)
    return np.cos(p32), np.sin(p32)
