"""The gridded rays of one cast: the compiled search (services/sensors/wave_kernel.py) over
every downward ray at once, on every core for a large cast, and the merging of the exact
march's hits.

A ray whose band segment (where it is between the grid's lowest and highest points) lies
on the grid gets its first crossing of the bilinear surface there; the rays leaving the
grid are returned for the exact march (services/sensors/water.py).

A large cast (a camera frame) is dealt out in batches of chunks: the calling thread and one
helper thread per other core each take the next batch as they come free, so a core the
machine holds back for a while leaves its share to the others. numba's own parallel loop
split the chunks between its threads in fixed halves, and on a shared 2-core VM the slower
core held every pass: a frame's pass took 9-10.5 ms at the median (one thread: 9.3 ms)
against 5.4-6.5 ms dealt out, side by side.
"""

from __future__ import annotations

import functools
import itertools
import os
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor, wait
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from catabot.bus.messages import CLASS_WATER
from services.sensors.common import Nearest
from services.sensors.wave_bounds import bounds, origins, plain
from services.sensors.wave_grid import WaveGrid
from services.sensors.wave_kernel import CHUNK, chunks
from services.sensors.wave_march import marcher, sea_tables

F32 = NDArray[np.float32]
F64 = NDArray[np.float64]
Idx = NDArray[np.intp]
PARALLEL_RAYS = 65_536  # a smaller cast runs on the calling thread (waking others costs more)
BATCH = 4  # chunks a thread takes at once (4 096 rays)
ROW = np.dtype((np.void, 12))  # a float32 normal as one item: a 1D scatter is 2x a 2D one


@dataclass(frozen=True)
class CastRays:
    """One cast's rays as the compiled passes take them: origins (1, 3) when shared, else
    (N, 3), directions (N, 3), contiguous float64; the grid frame's rotation and its anchor
    (the shared origin, else the mean one)."""

    o: F64
    d: F64
    limit: F64
    rot: F64
    anchor: F64

    @classmethod
    def of(cls, o: F64, d: F64, limit: F64, rot: F64) -> CastRays:
        own = origins(o)
        return cls(own, plain(d), limit, rot, own[:, :2].mean(axis=0))

    @property
    def frame(self) -> F64:
        """anchor (2), then rot (2 x 2, row-major): what the passes place rays with."""
        return np.concatenate([self.anchor, self.rot.ravel()])


def cast_on_grid(
    grid: WaveGrid, rays: CastRays, near: Nearest, reach: tuple[float, float], *, normals: bool
) -> Idx:
    """Every downward ray of `rays` against the grid, nearer hits merged into `near` (with
    the surface's normals, or the calm one); returns the rays that leave the grid (for the
    exact march). reach: the planned band, which holds every covered ray's segment (the
    surface is within both it and the grid's extremes), and the cast's range."""
    band, max_range = reach
    spec = grid.spec
    top, bottom = min(grid.zmax + spec.eps, band), max(grid.zmin - spec.eps, -band)
    frame = np.concatenate([rays.frame, [grid.u0, grid.v0, 1.0 / grid.hu, 1.0 / grid.hv]])
    far = np.zeros(rays.d.shape[0], dtype=bool)
    near_ = (near.rng, near.normal, near.cls, near.inst, CLASS_WATER)
    cast = (rays.o, rays.d)
    surface = (grid.flat, (grid.nu, grid.nv), grid.rise, grid.blocks)
    args = (surface, frame, cast, (top, bottom, max_range), near_, far, normals)
    run_chunks(lambda span: chunks()(*args, span), rays.d.shape[0])
    return np.flatnonzero(far)


def run_chunks(run: Callable[[tuple[int, int]], None], rays: int) -> None:
    """`run` over every chunk of `rays` rays, each (first, last) span once: on the calling
    thread for a small cast, else dealt out in batches to it and the helpers."""
    count, helpers = -(-rays // CHUNK), _helpers() if rays >= PARALLEL_RAYS else None
    if helpers is None:
        run((0, count))
        return
    batches = itertools.count()  # next() is atomic: each batch goes to one thread

    def work() -> None:
        while (first := next(batches) * BATCH) < count:
            run((first, min(first + BATCH, count)))

    pool, size = helpers
    helping = [pool.submit(work) for _ in range(size)]
    try:
        work()
    finally:
        wait(helping)
    for done in helping:
        done.result()  # a helper's error is the caster's


def cores() -> int:
    """The cores this process may run on."""
    if hasattr(os, "sched_getaffinity"):
        return len(os.sched_getaffinity(0))
    return os.cpu_count() or 1


@functools.cache
def _helpers() -> tuple[ThreadPoolExecutor, int] | None:
    """One helper thread per other core, started by the first large cast; None on one."""
    size = cores() - 1
    return (ThreadPoolExecutor(size, thread_name_prefix="wave-pass"), size) if size else None


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


def warm_up() -> None:
    """Load numba and every wave kernel, compiled or from the cache, and run each once on
    the argument types the casts use: a sea with waves (WaveCaster) calls this as it is set,
    so no tick pays it."""
    frame = np.array([0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 1.0])  # cells of 1 m
    rays = np.array([[1.5, 1.5, 1.0]]), np.array([[0.1, 0.1, -1.0]])
    near = np.full(1, np.inf), np.zeros((1, 3), np.float32), np.zeros(1, np.uint8)
    flat, helpers = np.zeros(48, np.float32), bounds()
    top = helpers.block_tops(flat, (4, 4), 4)
    surface = flat, (4, 4), helpers.surface_bounds(flat, (4, 4))[2:], (top, top.shape, 4)
    chunks()(surface, frame, rays, (0.5, -0.5, 9.0), (*near, np.zeros(1, np.int32), 1),
             np.zeros(1, bool), True, (0, 1))  # fmt: skip
    helpers.band_ends((rays[0], rays[1], np.ones(1)), frame[:6], 0.5, 1, np.empty(1))
    one = np.ones(1)
    sea = sea_tables(one, one * 0.0, one * 0.1)
    marcher()(sea, one * 0.0, rays[0], rays[1], np.ones(1), np.empty(1), np.zeros((1, 3)))
