"""The gridded rays of one cast: Newton, normals, the first-root proof, merging.

Per block of at most BLOCK rays (larger temporaries cost more than they save): the band
segment of every downward ray, its cell-unit form, Newton from where it crosses z = 0
(services/sensors/wave_trace.py) and the normal at its root. A ray steeper than every slope
of the interpolant along its direction crosses it once: its root is its hit. For the others
the root is proven first, or searched, once per cast (`wave_trace.verify`): the block maxima
clear the ray up to a window before the root, and the window is proven by the slope at the
root (`_window`). The few rays the search cannot settle within its CAP intervals, and the
rays leaving the grid, take the exact march (services/sensors/water.py).

Per-ray data stay contiguous and are picked with np.take: on 8 k rays a boolean-mask
selection costs ~18 us, a row-and-column fancy index ~80 us, an add ~1.4 us.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from catabot.bus.messages import CLASS_WATER
from catabot.world.waves import WaveField
from services.sensors import wave_trace as wt
from services.sensors.common import Nearest, rows_of
from services.sensors.water import march_hits
from services.sensors.wave_grid import WaveGrid

F32 = NDArray[np.float32]
F64 = NDArray[np.float64]
Idx = NDArray[np.intp]
BLOCK = 16384
STEEP_MARGIN = 1e-5  # relative: a ray this close to the steepest slope counts as grazing
TOLERANCE_M = 0.01  # a hit is proven first if no crossing before it dips deeper than this
TABLE_RAYS_PER_CELL = 2.0  # rays (of any direction) per cell from which cell tables pay
ROW = np.dtype((np.void, 12))  # a float32 normal as one item: a 1D scatter is 2x a 2D one


@dataclass(frozen=True)
class CastRays:
    """One cast's rays with their origin(s) in the grid frame, metres from `anchor` (the
    shared origin, else the mean one): uv (2,) for a shared origin (zero), else (2, N)."""

    o: F64
    d: F64
    limit: F64
    rot: F64
    anchor: F64
    uv: F64
    oz: float  # the shared origin's height (nan when the rays have their own)

    @classmethod
    def of(cls, o: F64, d: F64, limit: F64, rot: F64) -> CastRays:
        if o.strides[0] == 0:
            return cls(
                o, d, limit, rot, np.array(o[0, :2], np.float64), np.zeros(2), float(o[0, 2])
            )
        anchor = o[:, :2].mean(axis=0)
        return cls(o, d, limit, rot, anchor, rot @ (o[:, :2] - anchor).T, float("nan"))

    @property
    def uv_min(self) -> F64:
        """What the grid box must hold besides the segments: a shared origin."""
        return self.uv if self.uv.ndim == 1 else np.full(2, np.inf)

    @property
    def uv_max(self) -> F64:
        return self.uv if self.uv.ndim == 1 else np.full(2, -np.inf)


class GridPass:
    """The rays of one cast on a grid, block by block, then the doubtful ones together."""

    def __init__(
        self,
        grid: WaveGrid,
        rays: CastRays,
        near: Nearest,
        band: float,
        sea: tuple[WaveField, float],
    ) -> None:
        self.grid, self.rays, self.near = grid, rays, near
        self.waves, self.time_s = sea
        spec = grid.spec
        # the planned band holds every covered ray's segment; the surface is within both
        self.top, self.bottom = min(grid.zmax + spec.eps, band), max(grid.zmin - spec.eps, -band)
        self.margin = TOLERANCE_M - spec.eps - wt.LAMBDA_M
        self.curv = spec.curvature_uv
        self.to_cells = (spec.rot / [[grid.hu], [grid.hv]]).astype(np.float32)
        self.doubt: list[tuple[Idx, F32, F32, F32, F32, F32]] = []
        self.far: list[Idx] = []

    def run(self) -> Idx:
        """Every downward ray; returns those that leave the grid (for the exact march)."""
        n = self.rays.d.shape[0]
        if n > TABLE_RAYS_PER_CELL * (self.grid.nu - 1) * (self.grid.nv - 1):
            self.grid.tabulate()
        for s in range(0, n, BLOCK):
            self._block(s + np.flatnonzero(self.rays.d[s : s + BLOCK, 2] < -1e-12))
        if self.doubt:
            self._search(*(np.concatenate(parts) for parts in zip(*self.doubt, strict=True)))
        return np.concatenate(self.far) if self.far else np.empty(0, np.intp)

    def _segments(self, idx: Idx) -> tuple[wt.GridRays, F32, F32, F32]:
        """Rays `idx` in cell units, with where each enters the band, where its segment on
        the grid ends (the limit or the bottom) and where it reaches the bottom (float32)."""
        g, rays = self.grid, self.rays
        d = np.take(rays.d, idx, axis=0).astype(np.float32).T  # (3, n)
        oz: F32 | float
        if rays.uv.ndim == 1:
            uv, oz = rays.uv[:, None], rays.oz
        else:
            uv = np.take(rays.uv, idx, axis=1)
            oz = np.take(rays.o, idx, axis=0)[:, 2].astype(np.float32)
        f0 = ((uv - [[g.u0], [g.v0]]) / [[g.hu], [g.hv]]).astype(np.float32)
        dz: F32 = np.ascontiguousarray(d[2])
        inv = np.float32(1.0) / dz
        ta: F32 = (np.float32(self.top) - oz) * inv
        np.maximum(ta, 0.0, out=ta)
        tb: F32 = (np.float32(self.bottom) - oz) * inv
        te: F32 = np.minimum(tb, np.take(rays.limit, idx).astype(np.float32))
        return wt.GridRays(f0, self.to_cells @ d[:2], oz, dz), ta, te, tb

    def _block(self, idx: Idx) -> None:
        rays, lo, hi, tb = self._segments(idx)
        g = self.grid
        far = rays.b * hi  # where each segment ends (cells): inside the grid?
        far += rays.f0
        inside = (far[0] >= 1.0) & (far[0] <= g.nu - 2.0) & (far[1] >= 1.0) & (far[1] <= g.nv - 2.0)
        if rays.f0.shape[1] > 1:  # own origins: the start as well
            near = rays.b * lo
            near += rays.f0
            inside &= (near[0] >= 1.0) & (near[0] <= g.nu - 2.0)
            inside &= (near[1] >= 1.0) & (near[1] <= g.nv - 2.0)
        live = lo < hi
        out = np.flatnonzero(live & ~inside)
        if out.size:
            self.far.append(np.take(idx, out))
        keep = np.flatnonzero(live & inside)
        if keep.size < idx.size:
            idx, rays = np.take(idx, keep), rays.take(keep)
            lo, hi, tb = np.take(lo, keep), np.take(hi, keep), np.take(tb, keep)
        if idx.size == 0 or self._entry(idx, rays, lo):
            return
        start = np.clip(-rays.oz / rays.dz, lo, hi)
        slope = np.abs(rays.b[0]) * np.float32(g.hu * g.slope_u)
        slope += np.abs(rays.b[1]) * np.float32(g.hv * g.slope_v)
        steep = -rays.dz > slope * np.float32(1.0 + STEEP_MARGIN)
        rows = np.flatnonzero(steep)
        if rows.size:  # one root: the hit, if before hi
            sub, lo_s, hi_s = rays.take(rows), np.take(lo, rows), np.take(hi, rows)
            t, done = wt.steep_newton(g, sub, np.take(start, rows), lo_s, hi_s)
            hit = np.flatnonzero(done & (t <= hi_s))
            th = np.maximum(np.take(t, hit), np.take(lo_s, hit))
            self._hits(np.take(idx, np.take(rows, hit)), th, wt.gradient(g, sub.take(hit), th))
        rows = np.flatnonzero(~steep)
        if rows.size:
            sub, lo_s, hi_s = rays.take(rows), np.take(lo, rows), np.take(hi, rows)
            t, done = wt.newton(g, sub, np.take(start, rows), lo_s, hi_s)
            self._doubtful(np.take(idx, rows), sub, (t, done), (lo_s, hi_s), np.take(tb, rows))

    def _doubtful(
        self,
        idx: Idx,
        rays: wt.GridRays,
        solved: tuple[F32, NDArray[np.bool_]],
        span: tuple[F32, F32],
        tb: F32,
    ) -> None:
        """Non-steep rays: a converged root (or none before hi) is proven or searched in
        `verify` up to a window before it; the others are searched to hi."""
        t, done = solved
        lo, hi = span
        ok = np.flatnonzero(done)
        t_ok, lo_ok, hi_ok = np.take(t, ok), np.take(lo, ok), np.take(hi, ok)
        tq = np.minimum(np.maximum(t_ok, lo_ok), hi_ok)
        probe = rays.take(ok)
        window = self._window(probe, wt.gradient(self.grid, probe, tq))
        known = np.where(t_ok <= hi_ok, tq, np.float32(np.inf))
        end = np.maximum(tq - window, lo_ok)
        self._doubt(np.take(idx, ok), (lo_ok, end, known), hi_ok, np.take(tb, ok))
        fail = np.flatnonzero(~done)
        lo_f, hi_f = np.take(lo, fail), np.take(hi, fail)
        never = np.full(fail.size, np.inf, np.float32)
        self._doubt(np.take(idx, fail), (lo_f, hi_f, never), hi_f, np.take(tb, fail))

    def _entry(self, idx: Idx, rays: wt.GridRays, lo: F32) -> bool:
        """Rays that start under the surface (inside the band, f(0) <= 0) hit it at 0, as on
        the exact march; True when that is every ray of the block (a shared origin)."""
        inside = np.flatnonzero(lo <= 0.0)
        if inside.size == 0:
            return False
        shared = rays.f0.shape[1] == 1
        probe = inside[:1] if shared else inside
        zero = np.zeros(probe.size, np.float32)
        under = np.flatnonzero(wt.cell_f(self.grid, rays.take(probe), zero) <= 0.0)
        if shared:
            if under.size == 0:
                return False
            under = np.arange(inside.size)
        rows = np.take(inside, under)
        zero = np.zeros(rows.size, np.float32)
        self._hits(np.take(idx, rows), zero, wt.gradient(self.grid, rays.take(rows), zero))
        return shared and rows.size == lo.size

    def _window(self, rays: wt.GridRays, grad: F32) -> F32:
        """How far before its root a ray is proven to stay above -TOLERANCE_M of the surface,
        from f' <= P there and |f''| <= C: the largest L with -e - P L - C L^2 / 2 >= -TOL
        (e the error of the root), L = 2 m / (sqrt(P^2 + 2 C m) + P), m = TOL - e."""
        spec = self.grid.spec
        du, dv = rays.b[0] * np.float32(self.grid.hu), rays.b[1] * np.float32(self.grid.hv)
        p = rays.dz - grad[0] * du
        p -= grad[1] * dv
        p += np.float32(spec.grad_err[0]) * np.abs(du)
        p += np.float32(spec.grad_err[1]) * np.abs(dv)
        k = self.curv
        c = du * du * np.float32(k[0, 0])
        c += du * dv * np.float32(2.0 * k[0, 1])
        c += dv * dv * np.float32(k[1, 1])
        m = np.float32(self.margin)
        den = np.sqrt(p * p + c * (2.0 * m))
        den += p
        return np.divide(2.0 * m, den, out=np.full(den.shape, np.inf, np.float32), where=den > 0.0)

    def _doubt(self, idx: Idx, span: tuple[F32, F32, F32], hi: F32, tb: F32) -> None:
        """Rays to search from span[0] to span[1]; if they meet nothing there, their root
        span[2] (inf: none) is their hit. hi: where the grid segment ends, tb: the bottom."""
        if idx.size:
            self.doubt.append((idx, *span, hi, tb))

    def _hits(self, idx: Idx, t: F32, grad: F32) -> None:
        """Merge hits; normals from the gradient (grid frame -> world: g_xy = rot^T g_uv)."""
        g = self.grid.spec.rot.T.astype(np.float32) @ grad
        scale = 1.0 / np.sqrt(1.0 + g[0] * g[0] + g[1] * g[1])
        g *= -scale
        normal = np.stack([g[0], g[1], scale], axis=1)
        merge(self.near, idx, t.astype(np.float64), normal)

    def _search(self, idx: Idx, start: F32, end: F32, known: F32, hi: F32, tb: F32) -> None:
        """Rays whose first root is not proven: their unclear intervals searched (a known
        root past them is the hit if they meet nothing); those with more than wt.CAP
        unclear intervals are marched exactly from where the search stopped."""
        rays = self._segments(idx)[0]
        dip = TOLERANCE_M - 1e-4  # float32 rounding of the samples' f
        t, state, stop = wt.verify(self.grid, rays, start, end, known, dip)
        found = np.flatnonzero(state == wt.HIT)
        tf = np.take(t, found)
        self._hits(np.take(idx, found), tf, wt.gradient(self.grid, rays.take(found), tf))
        left = np.flatnonzero(state == wt.FAIL)
        if left.size:
            self._march(
                np.take(idx, left), np.take(stop, left), np.take(hi, left), np.take(tb, left)
            )

    def _march(self, idx: Idx, start: F32, hi: F32, tb: F32) -> None:
        """The exact march from `start` to `hi`, f(start) evaluated (the search saw the ray
        above the interpolant there, which is not quite above the sea)."""
        o, d = rows_of(self.rays.o, idx), np.take(self.rays.d, idx, axis=0)
        end = hi.astype(np.float64)
        unknown = np.zeros(idx.size, dtype=bool)
        rows, t, normal = march_hits(
            self.waves, o, d, (start.astype(np.float64), end), end < tb, self.time_s, unknown
        )
        merge(self.near, np.take(idx, rows), t, normal)


def merge(near: Nearest, rows: Idx, t: F64, normal: F32 | F64) -> None:
    """Rays whose water hit is nearer than their hit so far take it."""
    closer = t < np.take(near.rng, rows)
    normal32: F32 = np.asarray(normal, dtype=np.float32)
    if not closer.all():
        keep = np.flatnonzero(closer)
        rows, t, normal32 = np.take(rows, keep), np.take(t, keep), np.take(normal32, keep, axis=0)
    near.rng[rows] = t
    normal32 = np.ascontiguousarray(normal32)
    if near.normal.flags.c_contiguous:
        near.normal.view(ROW).reshape(-1)[rows] = normal32.view(ROW).reshape(-1)
    else:
        near.normal[rows] = normal32
    near.cls[rows], near.inst[rows] = CLASS_WATER, 0
