"""Water hits of one cast on a wave surface: on a grid where that pays, the exact march elsewhere.

Plan. A downward ray can meet the sea only inside the surface's band, first guessed as
+-BAND_SIGMAS sigma (sigma = Hs / 4: the medium preset's surface spans +-1.1 m where its
amplitudes sum to 3.0 m), then checked against the grid's own extremes (planned again with
the sum of amplitudes if they stick out). The grid is a box in the frame of the spectrum's
principal axes about the rays' origin, chosen among squares of growing size (clipped to
the footprint of the rays' band segments, from a sample of ~4 k rays) by estimated cost:
its nodes (node_ns), the rays wholly inside it (GRID_NS each) and the rays that leave it,
which take the exact march of services/sensors/water.py (exact_ns). A camera's few rays
reaching past ~150 m go exact; a chop too short for a grid of affordable size goes exact
altogether. The rays are then solved on the grid by services/sensors/wave_pass.py (its
compiled loop, wave_kernel.py, ~70 ns a ray).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from catabot.world.waves import WaveField
from services.sensors.common import Nearest, rows_of
from services.sensors.water import wave_hits
from services.sensors.wave_bounds import bounds
from services.sensors.wave_grid import GridSpec, Scratch, WaveGrid, grid_spec
from services.sensors.wave_pass import CastRays, cast_on_grid, merge, warm_up

F64 = NDArray[np.float64]
Idx = NDArray[np.intp]
BAND_SIGMAS = 4.5
SAMPLE = 4096  # rays the plan looks at
SMALL_CAST = 2048  # rays: fewer go to the exact march unplanned (measured crossover ~2 k)
MARGIN = 0.02  # of the sampled footprint, added around it
MAX_NODES = 2_000_000  # 24 MB of node tables at most
GRID_NS, GRID_FIXED_NS = 70.0, 200_000.0  # a gridded ray; the rest of a cast (measured)
GRAZING = 1.4  # a camera's 729 rays beyond its grid: 0.55 us each (more Newton steps)
SIZES = 0.7 ** np.arange(12)  # grid boxes tried, as fractions of the whole footprint


def node_ns(components: int) -> float:
    """Building one node: its row of the (nu, 2M) @ (2M, 3 nv) matmul and its block maxima
    (measured 12-18 ns for 48 components, 20-76 k nodes, plus ~0.1 ms a grid)."""
    return 2.0 + 0.2 * components


def exact_ns(components: int) -> float:
    """One ray in the band on the compiled exact march: ~10 evaluations of ~0.6 ns a
    component (measured 0.37-0.41 us for 48 components, 1-16 k LiDAR-like rays, where a
    gridded ray costs 0.07). A ray leaving a grid grazes the sea: GRAZING times that."""
    return 10.0 * (10.0 + 0.6 * components)


@dataclass(frozen=True)
class _Footprint:
    """The sampled rays' band segments: Chebyshev radius of their ends about the anchor
    (sorted), their bounding box with the origin (grid frame), and the rays they stand for."""

    radius: F64
    box: tuple[F64, F64]
    rays: float


class WaveCaster:
    """The wave surface of a Scene: one per sea (`Scene.set_waves`), reused cast to cast."""

    def __init__(self, waves: WaveField) -> None:
        self.waves = waves
        self.amplitude = float(np.sum(waves.amplitudes_m))
        self.spec: GridSpec | None = grid_spec(waves)
        if not waves.is_calm:
            warm_up()  # the kernels load (or compile) now, not inside the first cast
        sigma = waves.sigma_m
        self.guess = min(self.amplitude, BAND_SIGMAS * sigma)
        self.scratch = Scratch()
        self.last_plan = ""  # what the last cast did (benchmarks, tests)

    def cast(
        self, o: F64, d: F64, max_range: float, near: Nearest, time_s: float, *, normals: bool
    ) -> None:
        """Give the rays that meet the water before anything else the water's hit (and its
        normal, or the calm one where `normals` is False, on the grid)."""
        limit = np.minimum(near.rng, max_range)
        spec = self.spec
        if spec is None:
            self._exact(near, o, d, limit, None, time_s)
            return
        if d.shape[0] < SMALL_CAST:  # a radar tick: no grid pays for its fixed costs
            self.last_plan = "exact"
            self._exact(near, o, d, limit, None, time_s)
            return
        rays = CastRays.of(o, d, limit, spec.rot)
        band = self.guess
        for _ in range(2):
            box = self._plan(rays, band, spec)
            if box is None:
                self.last_plan = "exact"
                self._exact(near, o, d, limit, None, time_s)
                return
            grid = WaveGrid(spec, self.waves, time_s, rays.anchor, box, self.scratch)
            if grid.zmax + spec.eps <= band and grid.zmin - spec.eps >= -band:
                break
            band = self.amplitude  # the surface left the guessed band: plan with the bound
        far = cast_on_grid(grid, rays, near, (band, max_range), normals=normals)
        self.last_plan = f"grid {grid.nu} x {grid.nv}, {far.size} rays exact"
        self._exact(near, o, d, limit, far, time_s)

    def _exact(
        self, near: Nearest, o: F64, d: F64, limit: F64, idx: Idx | None, time_s: float
    ) -> None:
        """The exact march for the rays `idx` (None: all)."""
        if idx is None:
            merge(near, *wave_hits(self.waves, o, d, limit, time_s))
        elif idx.size:
            sub = rows_of(o, idx), np.take(d, idx, axis=0), np.take(limit, idx)
            rows, t, normal = wave_hits(self.waves, *sub, time_s)
            merge(near, np.take(idx, rows), t, normal)

    def _plan(self, rays: CastRays, band: float, spec: GridSpec) -> tuple[F64, F64] | None:
        """The cheapest box, or None when no grid beats the march: squares shrinking by 0.7
        from the whole footprint."""
        foot = _footprint(rays, band, self.scratch)
        if foot is None:
            return None
        m, n = self.waves.amplitudes_m.size, foot.rays
        sizes = float(foot.radius[-1]) * SIZES * 1.02
        lo, hi = np.maximum.outer(-sizes, foot.box[0]), np.minimum.outer(sizes, foot.box[1])
        nodes = ((hi[:, 0] - lo[:, 0]) / spec.hu + 3.0) * ((hi[:, 1] - lo[:, 1]) / spec.hv + 3.0)
        inside = np.searchsorted(foot.radius, sizes, side="right") * (n / foot.radius.size)
        cost = GRID_FIXED_NS + node_ns(m) * nodes + GRID_NS * inside
        cost += GRAZING * exact_ns(m) * (n - inside)
        cost[nodes > MAX_NODES] = np.inf
        best = int(np.argmin(cost))
        if cost[best] >= exact_ns(m) * n:
            return None
        return lo[best], hi[best]


def _footprint(rays: CastRays, band: float, scratch: Scratch) -> _Footprint | None:
    """The band segments of a sample of the downward rays (every k-th ray)."""
    n = rays.d.shape[0]
    step = max(1, n // SAMPLE)
    radius = scratch.get("plan_radius", (n // step + 1,), np.float64)
    m, box = bounds().band_ends((rays.o, rays.d, rays.limit), rays.frame, band, step, radius)
    if m == 0:
        return None
    lo, hi = np.array(box[:2]), np.array(box[2:])
    margin = MARGIN * (hi - lo)  # for the rays between the sampled ones
    return _Footprint(np.sort(radius[:m]), (lo - margin, hi + margin), float(m * step))
