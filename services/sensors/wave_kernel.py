"""First crossings of rays with the bilinear wave surface of a WaveGrid: one compiled loop.

Why compiled: a NumPy search cost ~1 000 calls a scan; a loop takes tens of ns a ray. In a
cell the bilinear surface along a ray is a quadratic in t, solved exactly. A ray steeper
than every slope of the interpolant along its direction crosses it once: Newton from the
height of the previous steep ray's hit, each step the cell's quadratic, kept in a bracket
(99% settle in one step). Any other ray walks the blocks of cells its band segment passes
(a 2D DDA) from where it enters the band: a block, then a cell, whose highest node is below
the ray where the ray leaves it is passed (the bilinear surface is no higher than its
nodes); in any other cell the quadratic gives the first crossing there, if any. So the hit
is the first root of the interpolant, which is within the grid's eps of the sea: no
crossing of the sea before it dips deeper than eps. A large cast's chunks of rays run on
every core (services/sensors/wave_pass.py).

Positions in cell units, f = f0 + t b (t in metres along the ray), heights in metres; node
(i, j) is flat[i * row + NODE j] (row = NODE nv), its d/du, d/dv the next two: a cell's
heights and gradients lie on two short runs of memory.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray

from services.sensors.wave_bounds import (
    F64,
    NODE,
    Nodes,
    Pair,
    compiled_fused,
    compiled_inline,
    jit_marked,
)

Ray = tuple[float, float, float, float, float, float, float]  # fu, fv, bu, bv, oz, dz, 1 / dz
Hit = tuple[float, int, int]  # t (inf: none) and the cell it lies in
Level = tuple[NDArray[np.float32], Pair, int]  # each block's highest node, blocks, cells a side
Dda = tuple[int, int, int, float, float, int, float, float]  # i, j, su, tu, du, sv, tv, dv
STEEP_STEPS = 48  # a cap: Newton in a bracket takes 1-2, bisection would need ~40
Span = tuple[float, float]  # lo, hi: metres along a ray
Reach = tuple[float, float, float]  # the band's top and bottom, the cast's range
Cast = tuple[F64, F64, F64]  # frame, origins, directions
Surface = tuple[Nodes, Pair, tuple[float, float], Level]
Near = tuple[F64, NDArray[np.float32], NDArray[np.uint8], NDArray[np.int32], int]
ROOT_M = 1e-6  # |f| at which a steep ray's Newton ends between cells
CHUNK = 1024  # rays whose hits one thread finds in turn
GROWTH = 1e-9  # a quadratic root this far outside its interval still counts (rounding)


@compiled_inline
def _coefficients(flat: Nodes, k: int, row: int) -> tuple[float, float, float, float]:
    """The cell's bilinear coefficients c0, cu, cv, cuv: g = c0 + cu wu + cv wv + cuv wu wv."""
    h00, h10 = float(flat[k]), float(flat[k + row])
    h01, h11 = float(flat[k + NODE]), float(flat[k + row + NODE])
    return h00, h10 - h00, h01 - h00, h11 - h10 - h01 + h00


@compiled_inline
def _first_root(c: float, b: float, a: float, length: float) -> float:
    """The least s in [0, length] with c + b s + a s^2 = 0, given c > 0; inf if none. It
    is 2 c / (sqrt(b^2 - 4 a c) - b) whatever the signs (the stable form of the root
    nearest 0 from above; a = 0 included), and there is none where that is not positive."""
    disc = b * b - 4.0 * a * c
    if disc < 0.0:
        return math.inf
    den = math.sqrt(disc) - b
    if den <= 0.0:
        return math.inf
    s = (c + c) / den
    return s if s <= length + GROWTH else math.inf


@compiled_inline
def _gap(flat: Nodes, row: int, cell: Pair, ray: Ray, t: float) -> tuple[float, float, float]:
    """f = z - g at t along the ray, with its slope and curvature in t inside `cell`."""
    fu, fv, bu, bv, oz, dz, _ = ray
    c0, cu, cv, cuv = _coefficients(flat, cell[0] * row + cell[1] * NODE, row)
    wu, wv = fu + t * bu - cell[0], fv + t * bv - cell[1]
    f = oz + t * dz - (c0 + cu * wu + cv * wv + cuv * wu * wv)
    return f, dz - (cu * bu + cv * bv + cuv * (wu * bv + wv * bu)), -cuv * bu * bv


@compiled_inline
def _top(flat: Nodes, row: int, cell: Pair) -> float:
    """The cell's highest corner: the bilinear surface over it is no higher."""
    k = cell[0] * row + cell[1] * NODE
    return max(max(flat[k], flat[k + NODE]), max(flat[k + row], flat[k + row + NODE]))


@compiled_inline
def _cell_of(cells: Pair, ray: Ray, t: float) -> Pair:
    i = min(max(math.floor(ray[0] + t * ray[2]), 0), cells[0] - 1)
    return i, min(max(math.floor(ray[1] + t * ray[3]), 0), cells[1] - 1)


@compiled_inline
def _axis(f: float, b: float, i: int) -> tuple[int, float, float]:
    """A 2D DDA along one axis from cell i: the step, the t of the next cell boundary and
    the t a cell takes."""
    if b == 0.0:
        return 1, math.inf, math.inf
    step = 1 if b > 0.0 else -1
    return step, (i + (1 if step > 0 else 0) - f) / b, abs(1.0 / b)


@compiled_inline
def _dda(shape: Pair, ray: Ray, t: float) -> Dda:
    """The cell of `shape` the ray is in at t and how it steps on (a 2D DDA's state)."""
    i, j = _cell_of(shape, ray, t)
    su, tu, du = _axis(ray[0], ray[2], i)
    sv, tv, dv = _axis(ray[1], ray[3], j)
    return i, j, su, tu, du, sv, tv, dv


@compiled_inline
def _step(s: Dda) -> Dda:
    """Into the next cell: across whichever boundary the ray meets first."""
    i, j, su, tu, du, sv, tv, dv = s
    if tu <= tv:
        return i + su, j, su, tu + du, du, sv, tv, dv
    return i, j + sv, su, tu, du, sv, tv + dv, dv


@compiled_inline
def _within(shape: Pair, s: Dda) -> bool:
    return 0 <= s[0] < shape[0] and 0 <= s[1] < shape[1]


@compiled_inline
def _scaled(ray: Ray, size: int) -> Ray:
    """The ray in units of blocks of `size` cells."""
    k = 1.0 / size
    return ray[0] * k, ray[1] * k, ray[2] * k, ray[3] * k, ray[4], ray[5], ray[6]


@compiled_fused
def _walk(flat: Nodes, row: int, cells: Pair, ray: Ray, lo: float, hi: float) -> Hit:
    """The first crossing in [lo, hi] of a ray walked cell by cell (inf: none): a cell whose
    highest corner is below the ray where it leaves the cell is passed."""
    s = _dda(cells, ray, lo)
    t0 = lo
    while t0 < hi and _within(cells, s):
        t1 = min(s[3], s[6], hi)
        if ray[4] + t1 * ray[5] <= _top(flat, row, (s[0], s[1])):
            f, slope, curve = _gap(flat, row, (s[0], s[1]), ray, t0)
            if f <= 0.0:
                return t0, s[0], s[1]
            root = _first_root(f, slope, curve, t1 - t0)
            if root < math.inf:
                return t0 + root, s[0], s[1]
        s, t0 = _step(s), t1
    return math.inf, 0, 0


@compiled_fused
def _walk_blocks(
    flat: Nodes, row: int, cells: Pair, level: Level, ray: Ray, lo: float, hi: float
) -> Hit:
    """The same walk a block of cells at a time: a block whose highest node is below the
    ray where it leaves the block is passed whole, the others walked cell by cell."""
    top, shape, size = level
    coarse = _scaled(ray, size)
    s = _dda(shape, coarse, lo)
    t0 = lo
    while t0 < hi and _within(shape, s):
        t1 = min(s[3], s[6], hi)
        if ray[4] + t1 * ray[5] <= top[s[0], s[1]]:
            hit = _walk(flat, row, cells, ray, t0, t1)
            if hit[0] < math.inf:
                return hit
        s, t0 = _step(s), t1
    return math.inf, 0, 0


@compiled_fused
def _steep(flat: Nodes, row: int, cells: Pair, ray: Ray, span: Span, z: float) -> Hit:
    """The one crossing in [lo, hi] = `span` of a ray steeper than the surface (f
    decreasing): Newton from where the ray is at height z, each step the cell's quadratic,
    kept inside the bracket. A ray that starts in the band (lo = 0) and under the surface
    hits it at once, as on the exact march."""
    lo, hi = span
    if lo <= 0.0:
        cell = _cell_of(cells, ray, lo)
        if _gap(flat, row, cell, ray, lo)[0] <= 0.0:
            return lo, cell[0], cell[1]
    a, b, b_seen = lo, hi, False
    t = min(max((z - ray[4]) * ray[6], lo), hi)
    for _ in range(STEEP_STEPS):
        i, j = _cell_of(cells, ray, t)
        f, slope, curve = _gap(flat, row, (i, j), ray, t)
        if abs(f) <= ROOT_M:
            return t, i, j
        if f > 0.0:
            if t >= hi:
                return math.inf, i, j  # above the surface where the segment ends
            a = t
        else:
            b, b_seen = t, True
        # the cell quadratic's root nearest t, ahead (f > 0) or behind: slope < 0 here
        nxt = t + (f + f) / (math.sqrt(max(slope * slope - 4.0 * curve * f, 0.0)) - slope)
        wu, wv = ray[0] + nxt * ray[2] - i, ray[1] + nxt * ray[3] - j
        if 0.0 <= wu <= 1.0 and 0.0 <= wv <= 1.0 and a <= nxt <= b:
            return nxt, i, j  # the cell's own root: the interpolant's
        bisect = 0.5 * (a + b) if b_seen else hi  # f(hi) is unknown until seen
        t = nxt if a < nxt < b else bisect
    return t, *_cell_of(cells, ray, t)


@compiled_inline
def _gradient(flat: Nodes, row: int, cell: Pair, ray: Ray, t: float) -> tuple[float, float]:
    """d eta/du, d eta/dv at t along the ray in `cell`: the bilinear interpolant of the
    exact node gradients."""
    wu, wv = ray[0] + t * ray[2] - cell[0], ray[1] + t * ray[3] - cell[1]
    k = cell[0] * row + cell[1] * NODE
    c0, cu, cv, cuv = _coefficients(flat, k + 1, row)
    gu = c0 + cu * wu + cv * wv + cuv * wu * wv
    c0, cu, cv, cuv = _coefficients(flat, k + 2, row)
    return gu, c0 + cu * wu + cv * wv + cuv * wu * wv


@compiled_inline
def _inside(cells: Pair, ray: Ray, t: float) -> bool:
    """Whether the point at t lies a cell or more inside the grid's edge."""
    pu, pv = ray[0] + t * ray[2], ray[1] + t * ray[3]
    return 1.0 <= pu <= cells[0] - 1.0 and 1.0 <= pv <= cells[1] - 1.0


@compiled_inline
def _in_cells(frame: F64, o: F64, d: F64) -> Ray:
    """A world ray in cell units: frame = anchor (2), rot (2 x 2, row-major), the grid's
    corner (u0, v0) and cells per metre (1 / hu, 1 / hv)."""
    x, y = o[0] - frame[0], o[1] - frame[1]
    fu = (frame[2] * x + frame[3] * y - frame[6]) * frame[8]
    fv = (frame[4] * x + frame[5] * y - frame[7]) * frame[9]
    bu = (frame[2] * d[0] + frame[3] * d[1]) * frame[8]
    bv = (frame[4] * d[0] + frame[5] * d[1]) * frame[9]
    return fu, fv, bu, bv, o[2], d[2], 1.0 / d[2]


@compiled_inline
def _normal(frame: F64, grad: tuple[float, float], out: NDArray[np.float32], r: int) -> None:
    """The upward unit normal from the grid-frame gradient (g_xy = rot^T g_uv)."""
    gx = frame[2] * grad[0] + frame[4] * grad[1]
    gy = frame[3] * grad[0] + frame[5] * grad[1]
    scale = 1.0 / math.sqrt(1.0 + gx * gx + gy * gy)
    out[r, 0], out[r, 1], out[r, 2] = -gx * scale, -gy * scale, scale


@compiled_fused
def _setup(cast: Cast, r: int, reach: Reach, limit: float) -> tuple[Ray, Span]:
    """Ray r in cell units and its segment in the band (lo >= hi: none)."""
    frame, o, d = cast
    ray = _in_cells(frame, o[0] if o.shape[0] == 1 else o[r], d[r])
    span = max((reach[0] - ray[4]) * ray[6], 0.0), min((reach[1] - ray[4]) * ray[6], limit)
    return ray, span


@compiled_fused
def _chunk(
    surface: Surface, frame: F64, rays: tuple[F64, F64], reach: Reach, near: Near,
    far: NDArray[np.bool_], normals: bool, c: int,
) -> None:  # fmt: skip
    """chunk_pass for chunk c: its rays are fixed whatever the threads, so its hits are. A
    steep ray's Newton starts at the last steep hit's height (99% settle in 1 step)."""
    (flat, (nu, nv), rise, blocks), (rng, normal, cls, inst, water) = surface, near
    row, cells = NODE * nv, (nu - 1, nv - 1)
    cast = (frame, rays[0], rays[1])
    z = 0.0  # the last steep hit's height
    for r in range(c * CHUNK, min(rays[1].shape[0], c * CHUNK + CHUNK)):
        if not rays[1][r, 2] < -1e-12:
            continue
        ray, span = _setup(cast, r, reach, min(rng[r], reach[2]))
        if span[0] >= span[1]:
            continue
        if not (_inside(cells, ray, span[0]) and _inside(cells, ray, span[1])):
            far[r] = True
            continue
        if -ray[5] > abs(ray[2]) * rise[0] + abs(ray[3]) * rise[1]:
            t, i, j = _steep(flat, row, cells, ray, span, z)
            z = ray[4] + t * ray[5] if t < math.inf else z
        else:
            t, i, j = _walk_blocks(flat, row, cells, blocks, ray, span[0], span[1])
        if t < rng[r]:
            rng[r], cls[r], inst[r] = t, water, 0
            if normals:
                _normal(frame, _gradient(flat, row, (i, j), ray, t), normal, r)
            else:
                normal[r, 0], normal[r, 1], normal[r, 2] = 0.0, 0.0, 1.0


@compiled_fused
def chunk_pass(
    surface: Surface, frame: F64, rays: tuple[F64, F64], reach: Reach, near: Near,
    far: NDArray[np.bool_], normals: bool, chunks: Pair,
) -> None:  # fmt: skip
    """Every downward ray of chunks first..last-1 (`chunks`; origins o: (1, 3) shared or
    (n, 3), directions d: (n, 3)) meets the interpolant at its first crossing in the band
    top..bottom (`reach` = top, bottom, max range), if that is nearer than its hit so far:
    near = (range, normal, class, instance, the water's class) updated in place. Rays whose
    band segment leaves the grid are flagged in `far` (the exact march's). normals: the
    surface's at each hit, else the calm one (up). surface: the node table, its shape, the
    steepest rise per cell along u and v (a ray descending faster crosses it once) and the
    block maxima. A chunk's rays are fixed, so its hits are whichever thread runs it
    (wave_pass.py deals the chunks of a large cast to every core)."""
    for c in range(chunks[0], chunks[1]):
        _chunk(surface, frame, rays, reach, near, far, normals, c)


@functools.cache
def chunks() -> Callable[..., None]:
    """The compiled `chunk_pass` (numba loaded, the module's kernels compiled or read from
    the cache, on the first call)."""
    return jit_marked(globals())["chunk_pass"]
