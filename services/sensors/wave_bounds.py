"""Compiled helpers of a cast's plan and grid: where the rays meet the band, the grid's
bounds. One pass over the arrays each, where NumPy took several (~0.15 ms a LiDAR scan).

And how the sensors' kernels are compiled. numba (llvmlite's compiler: ~110 MB resident) is
loaded by the first sea with waves, not by every sensors process: a function is marked
`@compiled` here and compiled, with the rest of its module, by `jit_marked` when its
module's loader (`bounds()`, wave_kernel's `chunks()`, wave_march's `marcher()`) is first
called; calls between marked functions reach the compiled ones because the module's own
names are rebound. Every kernel is cached on disk (a process loads one in ~0.1 s instead
of compiling it for ~4 s), runs without the GIL, and with NumPy's error model (x / 0 is inf,
as the code expects, with no check on every division); small helpers are inlined.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, TypeVar

import numpy as np
from numpy.typing import NDArray

Nodes = NDArray[np.float32]
F64 = NDArray[np.float64]
Pair = tuple[int, int]
Fn = TypeVar("Fn", bound=Callable[..., Any])
NODE = 3  # floats a node of the grid: height, d/du, d/dv
OPTIONS = "numba_options"  # where a marked function keeps how it is to be compiled


def compiled(fn: Fn) -> Fn:
    """Mark a kernel for `jit_marked`."""
    setattr(fn, OPTIONS, {})
    return fn


def compiled_inline(fn: Fn) -> Fn:
    """Mark a small helper, inlined into its callers."""
    setattr(fn, OPTIONS, {"inline": "always"})
    return fn


def compiled_fused(fn: Fn) -> Fn:
    """Mark a kernel whose a * b + c may be one fused multiply-add (one rounding, not two):
    its chains of dependent arithmetic are shorter (the grid pass ~10 % faster), and the
    result is the same on every run of one machine. Its inlined helpers take the same."""
    setattr(fn, OPTIONS, {"fastmath": {"contract"}})
    return fn


def compiled_sum(fn: Fn) -> Fn:
    """Mark a kernel whose float sums may be reordered, so its loop is vectorised: the same
    result on every run of one machine, not the strict left-to-right sum. Not inlined: an
    inlined body takes its caller's (strict) arithmetic."""
    setattr(fn, OPTIONS, {"fastmath": {"reassoc", "contract"}})
    return fn


def plain(a: F64) -> F64:
    """Contiguous, writable float64 (a copy only where needed): the one array type the
    kernels are compiled for (a read-only view, a shared origin's, would compile again)."""
    return np.require(a, np.float64, ["C", "W"])


def origins(o: F64) -> F64:
    """The rays' origins as the kernels take them: (1, 3) for a shared origin (a broadcast
    view, stride 0), else (n, 3); plain."""
    return plain(o[:1] if o.strides[0] == 0 else o)


def jit_marked(namespace: dict[str, Any]) -> dict[str, Any]:
    """Compile the marked functions of a module in place (its globals(), returned, its
    kernels now their compiled selves): idempotent. No kernel is numba-parallel: wave_pass
    deals a large cast's chunks to threads of its own, each as it comes free."""
    import numba  # ≈110 MB: only a process that meets waves pays it

    for name, fn in list(namespace.items()):
        options = getattr(fn, OPTIONS, None)
        if options is not None and not isinstance(fn, numba.core.dispatcher.Dispatcher):
            jit = numba.njit(cache=True, nogil=True, error_model="numpy", **options)
            namespace[name] = jit(fn)
    return namespace


Box = tuple[float, float, float, float]  # u_lo, v_lo, u_hi, v_hi


@compiled
def band_ends(
    rays: tuple[F64, F64, F64], frame: F64, band: float, step: int, radius: F64
) -> tuple[int, Box]:
    """Every step-th downward ray's segment in the band +-band, in the grid frame (frame:
    anchor (2), rot (2 x 2, row-major)): each segment's Chebyshev radius about the anchor
    into `radius`; returns their number and the box of the segments (and of a shared
    origin, o: (1, 3))."""
    o, d, limit = rays
    shared = o.shape[0] == 1
    box = (math.inf, math.inf, -math.inf, -math.inf)
    if shared:
        box = _grow(box, _uv(o[0, 0], o[0, 1], frame))
    m = 0
    for r in range(0, d.shape[0], step):
        k = 0 if shared else r
        dz = d[r, 2]
        if not dz < -1e-12:
            continue
        ta = max((band - o[k, 2]) / dz, 0.0)
        tb = min((-band - o[k, 2]) / dz, limit[r])
        if not ta < tb:
            continue
        a = _uv(o[k, 0] + ta * d[r, 0], o[k, 1] + ta * d[r, 1], frame)
        b = _uv(o[k, 0] + tb * d[r, 0], o[k, 1] + tb * d[r, 1], frame)
        box = _grow(_grow(box, a), b)
        radius[m] = max(max(abs(a[0]), abs(a[1])), max(abs(b[0]), abs(b[1])))
        m += 1
    return m, box


@compiled
def _uv(x: float, y: float, frame: F64) -> tuple[float, float]:
    x, y = x - frame[0], y - frame[1]
    return frame[2] * x + frame[3] * y, frame[4] * x + frame[5] * y


@compiled
def _grow(box: Box, p: tuple[float, float]) -> Box:
    return min(box[0], p[0]), min(box[1], p[1]), max(box[2], p[0]), max(box[3], p[1])


@compiled
def surface_bounds(flat: Nodes, shape: Pair) -> tuple[float, float, float, float]:
    """The lowest and highest node and the steepest rise between neighbouring nodes along
    u and along v (per cell: in a cell d g/du is a convex combination of its u-edges')."""
    nu, nv = shape
    row = NODE * nv
    low, high, rise_u, rise_v = math.inf, -math.inf, 0.0, 0.0
    for i in range(nu):
        for j in range(nv):
            h = flat[i * row + j * NODE]
            low, high = min(low, h), max(high, h)
            if i + 1 < nu:
                rise_u = max(rise_u, abs(flat[(i + 1) * row + j * NODE] - h))
            if j + 1 < nv:
                rise_v = max(rise_v, abs(flat[i * row + (j + 1) * NODE] - h))
    return low, high, rise_u, rise_v


@compiled
def block_tops(flat: Nodes, shape: Pair, size: int) -> NDArray[np.float32]:
    """The highest node of each block of size x size cells (its (size + 1)^2 nodes): the
    bilinear surface over the block is no higher."""
    nu, nv = shape
    row = NODE * nv
    top = np.full(((nu - 2) // size + 1, (nv - 2) // size + 1), -np.inf, np.float32)
    for bi in range(top.shape[0]):
        for bj in range(top.shape[1]):
            high = -np.inf
            for i in range(bi * size, min(bi * size + size + 1, nu)):
                for j in range(bj * size, min(bj * size + size + 1, nv)):
                    high = max(high, flat[i * row + j * NODE])
            top[bi, bj] = high
    return top


@dataclass(frozen=True)
class Bounds:
    """This module's compiled entry points."""

    band_ends: Callable[..., tuple[int, Box]]
    surface_bounds: Callable[[Nodes, Pair], tuple[float, float, float, float]]
    block_tops: Callable[[Nodes, Pair, int], NDArray[np.float32]]


@functools.cache
def bounds() -> Bounds:
    """The compiled helpers (numba loaded and the kernels compiled or read from the cache at
    the first call)."""
    jit_marked(globals())
    return Bounds(band_ends, surface_bounds, block_tops)
