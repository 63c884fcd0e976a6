"""Rays against the bilinear wave surface of a WaveGrid: first roots of f(t) = z(t) - g(t).

Along a ray inside one cell the bilinear surface is a quadratic in t, so a step solves that
quadratic exactly: if its root lies in the same cell it IS the root of the interpolant
(|z - eta| <= eps there), otherwise it is the next guess (a Newton step that knows the
cell's curvature). From where the ray crosses z = 0, 62% of a camera's steep rays end in one
step and 99.6% in two (`steep_newton`); the others (`newton`) keep a bracket and bisect
when a step would leave it, 3-5 steps.

Which root. A ray steeper than any slope of the interpolant along its direction crosses it
once; the others may pass over a trough and meet the next crest, so their root is checked
(`verify`): the ray is clear of the sea over an interval if its lowest point there is above
the highest node of the blocks of BLOCK_CELLS x BLOCK_CELLS cells the interval touches
(`_intervals`). Near the root those blocks hold the root itself, so the last stretch is
proven by the slope there instead (wave_pass.GridPass._window). The intervals left unclear
are sampled (`_fine`) and the first sign change solved; a crossing hidden between two
samples that both see the ray above the interpolant dips less than eps + C h^2 / 8 under
the sea (C the curvature bound along the ray, h the spacing), so the samples are spaced
(`_samples`) to keep that under the tolerance: 6 an interval for the medium sea, 11 for a
harbour chop. In the benchmark frames 79% of the camera's and 80% of the LiDAR's non-steep
rays are proven without sampling.

NumPy over rays in float32 (cell units; t in metres), arrays of at most ~16 k rays.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from services.sensors.wave_grid import BLOCK_CELLS, WaveGrid

F32 = NDArray[np.float32]
Idx = NDArray[np.intp]
LAMBDA_M = 2e-4  # |f| at which a Newton step ends without the in-cell root
NEWTON_STEPS = 5
BRACKET_STEPS = 24  # a sign change is bracketed: bisection alone gets within 2^-24 of it
MAX_FINE = 17  # samples of an unclear interval at most (the medium sea needs 6, a chop 11)
CAP = 16  # unclear intervals sampled per ray; a ray with more is marched exactly after
HIT, MISS, FAIL = 1, 2, 0


@dataclass(frozen=True)
class GridRays:
    """Rays in cell units: position f0 + t b (cells, rows u and v), height oz + t dz (m).
    f0 is (2, 1) and oz a float when the rays share their origin."""

    f0: F32
    b: F32
    oz: F32 | float
    dz: F32

    def take(self, keep: Idx) -> GridRays:
        f0 = self.f0 if self.f0.shape[1] == 1 else np.take(self.f0, keep, axis=1)
        oz = self.oz if np.ndim(self.oz) == 0 else np.take(self.oz, keep)
        return GridRays(f0, np.take(self.b, keep, axis=1), oz, np.take(self.dz, keep))


def _place(grid: WaveGrid, rays: GridRays, t: F32) -> tuple[F32, F32]:
    """(weights (2, n) of the position in its cell, the cell's (i, j) as floats)."""
    w = rays.b * t
    w += rays.f0
    base = np.floor(w)
    w -= base
    return w, base


def _corners(grid: WaveGrid, base: F32, which: Idx) -> F32:
    """Node values flat[cell corner + which] (len(which), n). The index and value arrays are
    the grid's scratch (a block's (8, 16 k) int64 indices are 1 MB: fresh, they page-fault
    on every call); the values live until the next call."""
    at = (grid.weights @ base).astype(np.intp)  # i * row + j, exact in float32 below 2^24
    shape = (which.shape[0], base.shape[1])
    idx = grid.scratch.get(f"corner_idx{shape[0]}", shape, np.intp)
    np.add(which, at, out=idx)
    return np.take(grid.flat, idx, out=grid.scratch.get(f"corner_val{shape[0]}", shape))


def _rows(table: F32, grid: WaveGrid, base: F32) -> F32:
    """The tabulated cells' rows, transposed: (row width, n), strided."""
    at = (grid.cell_weights @ base).astype(np.intp)[0]
    return np.take(table, at, axis=0).T


def _cell(grid: WaveGrid, rays: GridRays, t: F32) -> tuple[F32, F32, F32]:
    """(w, c, f): the weights, the cell's coefficients c0, cu, cv, cuv (rows of c, the
    surface g = c0 + wu (cu + wv cuv) + wv cv) and f = z - g."""
    w, base = _place(grid, rays, t)
    if grid.val is not None:
        c = _rows(grid.val, grid, base)
    else:
        c = _corners(grid, base, grid.corners)  # h00, h10, h01, h11 -> coefficients
        c[3] -= c[1]
        c[3] -= c[2]
        c[3] += c[0]
        c[1] -= c[0]
        c[2] -= c[0]
    g = w[1] * c[3]
    g += c[1]
    g *= w[0]
    g += c[0]
    g += w[1] * c[2]
    f = t * rays.dz
    f += rays.oz
    f -= g
    return w, c, f


def cell_f(grid: WaveGrid, rays: GridRays, t: F32) -> F32:
    """f = z - g at distances t along the rays."""
    return _cell(grid, rays, t)[2]


def steep_newton(
    grid: WaveGrid, rays: GridRays, t: F32, lo: F32, hi: F32, steps: int = NEWTON_STEPS
) -> tuple[F32, NDArray[np.bool_]]:
    """The root of the interpolant for rays steeper than any of its slopes (one root, f
    decreasing), from t, steps clipped to [lo, hi]: (t, done); t > hi: the root is past hi."""
    t_out, done = np.array(t, dtype=np.float32), np.zeros(t.size, dtype=bool)
    rows = np.arange(t.size)
    for step in range(steps):
        w, c, f = _cell(grid, rays, t)
        s, ok = _quadratic_step(w, c, f, rays)
        ok |= (f > 0.0) & (t >= hi)  # above the surface at hi: the root is past it
        s += t
        t_out[rows], done[rows] = s, ok
        keep = np.flatnonzero(~ok)
        if keep.size == 0 or step == steps - 1:
            break
        rows, rays = rows[keep], rays.take(keep)
        lo, hi = np.take(lo, keep), np.take(hi, keep)
        t = np.clip(np.take(s, keep), lo, hi)
    return t_out, done


def newton(
    grid: WaveGrid, rays: GridRays, t: F32, lo: F32, hi: F32, steps: int = NEWTON_STEPS
) -> tuple[F32, NDArray[np.bool_]]:
    """A root of the interpolant per ray in [lo, hi] (where the grid holds the ray; f(lo) >=
    0), from t: (t, done), t > hi for a ray above the surface at hi (no root before it).

    Steps to the cell quadratic's root stay inside the bracket [a, b] of the last points
    seen above (a) and under (b) the surface; a step that would leave it bisects instead,
    except that a ray still above the surface is first tried at hi."""
    n = t.size
    t_out, done = np.array(t, dtype=np.float32), np.zeros(n, dtype=bool)
    rows = np.arange(n)
    a, b = np.array(lo, dtype=np.float32), np.array(hi, dtype=np.float32)
    for step in range(steps):
        w, c, f = _cell(grid, rays, t)
        s, ok = _quadratic_step(w, c, f, rays)
        close = np.abs(f) <= LAMBDA_M  # on the surface already: stay
        np.copyto(s, 0.0, where=close)
        ok |= close
        s += t
        above = f > 0.0
        beyond = above & (t >= hi)  # above the surface at hi: no root in [lo, hi]
        s[beyond] = np.inf
        ok |= beyond
        t_out[rows], done[rows] = s, ok
        keep = np.flatnonzero(~ok)
        if keep.size == 0 or step == steps - 1:
            break
        np.copyto(a, t, where=above)
        np.copyto(b, t, where=~above)
        rows, rays = rows[keep], rays.take(keep)
        t, a, b, hi = (np.take(v, keep) for v in (s, a, b, hi))
        wild = ~((t > a) & (t < b))  # NaN too
        mid = (a + b) * np.float32(0.5)
        np.copyto(mid, hi, where=b >= hi)  # nothing under the surface yet: try hi
        np.copyto(t, mid, where=wild)
    return t_out, done


def _quadratic_step(w: F32, c: F32, f: F32, rays: GridRays) -> tuple[F32, NDArray[np.bool_]]:
    """The step s to the root of the cell's quadratic nearest the ray's position, and
    whether that root lies in the cell: there f(t + s) = f + beta s - bu bv cuv s^2."""
    beta = w[1] * c[3]
    beta += c[1]
    beta *= rays.b[0]
    slope_v = w[0] * c[3]
    slope_v += c[2]
    slope_v *= rays.b[1]
    beta += slope_v
    np.subtract(rays.dz, beta, out=beta)
    disc = rays.b[0] * rays.b[1]
    disc *= c[3]
    disc *= f
    disc *= 4.0
    disc += beta * beta
    ok = disc >= 0.0
    np.sqrt(np.maximum(disc, 0.0, out=disc), out=disc)
    disc -= beta  # the denominator of the stable root 2 f / (sqrt(disc) - beta)
    ok &= disc > 0.0
    s = np.divide(f + f, disc, out=np.zeros_like(f), where=ok)
    w += rays.b * s
    w -= 0.5
    np.abs(w, out=w)
    ok &= np.maximum(w[0], w[1]) <= 0.5
    return s, ok


def gradient(grid: WaveGrid, rays: GridRays, t: F32) -> F32:
    """(2, n) d eta/du, d eta/dv at distance t along each ray: the bilinear interpolant of the
    exact node gradients (error <= GridSpec.grad_err per axis)."""
    w, base = _place(grid, rays, t)
    if grid.grad is not None:
        c0, cu, cv, cuv = _rows(grid.grad, grid, base).reshape(4, 2, -1)  # (coef, axis, ray)
    else:
        h00, h10, h01, h11 = (
            _corners(grid, base, grid.grad_corners).reshape(2, 4, -1).transpose(1, 0, 2)
        )
        c0, cu, cv, cuv = h00, h10 - h00, h01 - h00, h11 - h10 - h01 + h00
    out = w[1] * cuv
    out += cu
    out *= w[0]
    out += c0
    out += w[1] * cv
    return out


def _intervals(
    grid: WaveGrid, rays: GridRays, t_a: F32, t_b: F32
) -> tuple[Idx, F32, NDArray[np.bool_], Idx, F32]:
    """Split [t_a, t_b] of each ray into intervals spanning at most BLOCK_CELLS cells per
    axis: (the ray of each interval, its start, whether the ray may meet the surface in it,
    the first interval of each ray (a ray with none has first[r] == first[r + 1]), the
    length). An interval is clear if the ray's lowest point on it (its end: rays go down)
    is above the highest node of the (at most 2 x 2) blocks it touches."""
    span = np.maximum(np.abs(rays.b[0]), np.abs(rays.b[1]))
    step = np.float32(BLOCK_CELLS) / np.maximum(span, np.float32(1e-6))
    count = np.ceil(np.maximum(t_b - t_a, 0.0) / step).astype(np.intp)
    first = np.zeros(count.size + 1, np.intp)
    np.cumsum(count, out=first[1:])
    ray = np.repeat(np.arange(count.size), count)
    ta = (np.arange(ray.size) - first[ray]).astype(np.float32)
    ta *= step[ray]
    ta += t_a[ray]
    tb = np.minimum(ta + step[ray], t_b[ray])
    sub = rays.take(ray)
    ends = [sub.b * ta, sub.b * tb]
    for end in ends:
        end += sub.f0
        end *= np.float32(1.0 / BLOCK_CELLS)
        np.floor(end, out=end)
    top = np.full(ray.size, -np.inf, np.float32)
    for bu in (ends[0][0], ends[1][0]):
        for bv in (ends[0][1], ends[1][1]):
            at = (bu * grid.blocks_v + bv).astype(np.intp)
            np.maximum(top, np.take(grid.block_max, at), out=top)
    low = tb * sub.dz
    low += sub.oz
    return ray, ta, low <= top, first, step


def verify(
    grid: WaveGrid, rays: GridRays, lo: F32, end: F32, known: F32, dip: float
) -> tuple[F32, NDArray[np.int8], F32]:
    """The first root of the interpolant in [lo, end] per ray, else `known` (inf: none):
    (t, state HIT / MISS / FAIL, where a FAIL ray's search stopped). The unclear intervals
    of every ray are sampled together (at most CAP a ray): one pass, whatever the number of
    false alarms before the root. Samples are close enough that a crossing of the sea
    between two of them that see the ray above the interpolant dips at most `dip` under
    it: f >= -eps at the samples and |f''| <= C, so the dip is under eps + C h^2 / 8."""
    t_out = np.array(known, dtype=np.float32)
    ray, ta, unclear, _, step = _intervals(grid, rays, lo, end)
    pick = np.flatnonzero(unclear)
    r = np.take(ray, pick)
    rank = np.arange(pick.size) - np.searchsorted(r, r)  # order among the ray's unclear ones
    cut = np.flatnonzero(rank < CAP)
    pick, r = np.take(pick, cut), np.take(r, cut)
    ta = np.take(ta, pick)
    tb = np.minimum(ta + np.take(step, r), np.take(end, r))
    count = _samples(grid, rays, step, dip)
    found, t, solved = _fine(grid, rays.take(r), ta, tb, count)
    hit = np.flatnonzero(found)
    lead = np.take(hit, np.flatnonzero(np.diff(np.take(r, hit), prepend=-1)))  # first per ray
    first = np.take(r, lead)
    t_out[first] = np.take(t, lead)
    state = np.where(np.isfinite(t_out), np.int8(HIT), np.int8(MISS))
    stop = np.array(end, dtype=np.float32)
    full = np.take(r, np.flatnonzero(rank[cut] == CAP - 1))  # rays with CAP unclear ones
    full = full[~np.isin(full, first)]
    state[full] = FAIL
    stop[full] = np.take(tb, np.searchsorted(r, full) + CAP - 1)
    lost = np.take(lead, np.flatnonzero(~np.take(solved, lead)))  # unsettled brackets
    state[np.take(r, lost)] = FAIL
    stop[np.take(r, lost)] = np.take(t, lost)
    return t_out, state, stop


def _samples(grid: WaveGrid, rays: GridRays, step: F32, dip: float) -> int:
    """Samples per interval of `step` so that eps + C h^2 / 8 <= dip on every ray (C its
    curvature bound, h the spacing): one count for the whole call, the largest."""
    k = grid.spec.curvature_uv
    du, dv = rays.b[0] * np.float32(grid.hu), rays.b[1] * np.float32(grid.hv)
    c = du * du * np.float32(k[0, 0]) + du * dv * np.float32(2.0 * k[0, 1])
    c += dv * dv * np.float32(k[1, 1])
    spacing = np.sqrt(8.0 * max(dip - grid.spec.eps, 1e-6) / np.maximum(c, 1e-12))
    need = int(np.ceil(np.max(step / spacing, initial=1.0))) + 1
    return min(max(need, 3), MAX_FINE)


def _fine(
    grid: WaveGrid, rays: GridRays, ta: F32, tb: F32, count: int
) -> tuple[NDArray[np.bool_], F32, NDArray[np.bool_]]:
    """The first sign change of f among `count` samples of [ta, tb], solved by Newton within
    its bracket: (found, t, solved); a bracket Newton does not settle (not seen on the bench
    scenes) is left unsolved with t at its start, where the exact march resumes. Samples
    are (count, n): NumPy reduces along the long axis ~50x faster than along a short one."""
    n = ta.size
    frac = np.linspace(0.0, 1.0, count, dtype=np.float32)[:, None]
    ts = ta + (tb - ta) * frac
    wide = rays.take(np.tile(np.arange(n), count))
    f = _cell(grid, wide, ts.ravel())[2].reshape(count, n)
    under = f <= 0.0
    found = under.any(axis=0)
    j = np.argmax(under, axis=0)
    cols = np.arange(n)
    t = np.where(found, ts[j, cols], np.inf).astype(np.float32)
    solved = np.ones(n, dtype=bool)
    rows = np.flatnonzero(found & (j > 0))
    if rows.size:
        jr = j[rows]
        a, b = ts[jr - 1, rows], ts[jr, rows]
        fa, fb = f[jr - 1, rows], f[jr, rows]
        guess = a + (b - a) * (fa / (fa - fb))  # the secant point: f(a) > 0 >= f(b)
        root, ok = newton(grid, rays.take(rows), guess, a, b, BRACKET_STEPS)
        ok &= (root >= a) & (root <= b)
        t[rows] = np.where(ok, root, a)
        solved[rows] = ok
    return np.asarray(found, dtype=bool), t, solved
