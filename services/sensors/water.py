"""Ray hits on the water surface z = eta(x, y, t): the same WaveField physics floats on.

Calm water is the plane z = 0: one division per ray. With waves, |eta| <= A (the sum of the
component amplitudes), so a downward ray can only cross the surface between the heights
z = +A and z = -A. That bracket (cut at the nearest other hit) is marched in MARCH_SAMPLES
steps to find the FIRST sign change of f(t) = z(t) - eta(x(t), y(t), t_now) (a grazing ray
can pass over a trough and meet the next crest), then refined by Illinois false position,
which converges superlinearly on the smooth surface: after REFINE_STEPS the hit is well
within 1 cm of the surface. Rays pointing up or level never hit water from above.

Cost: (downward rays in bracket) x (MARCH_SAMPLES + REFINE_STEPS) wave evaluations, each
costing one float32 cosine per wave component; calm water costs nothing of the sort.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from catabot.waves import WaveField

F64 = NDArray[np.float64]
MARCH_SAMPLES = 8
REFINE_STEPS = 10
TOLERANCE_M = 1e-4  # vertical distance to the surface at which a ray is done


def calm_hits(o: F64, d: F64, max_range: float) -> F64:
    """Distance along each unit ray to the plane z = 0 from above (inf: none within
    `max_range`); the normal there is +z."""
    with np.errstate(divide="ignore", invalid="ignore"):
        t = -o[:, 2] / d[:, 2]
    miss = ~((d[:, 2] < -1e-12) & (o[:, 2] >= 0.0) & (t <= max_range))
    t[miss] = np.inf
    return t


def wave_hits(
    waves: WaveField, amplitude: float, o: F64, d: F64, limit: F64, time_s: float
) -> tuple[NDArray[np.intp], F64, F64]:
    """The rays that meet the wave surface before `limit`, their distances and the
    surface's unit normals there (world frame)."""
    down = d[:, 2] < -1e-12
    with np.errstate(divide="ignore", invalid="ignore"):
        t_top = np.maximum((amplitude - o[:, 2]) / d[:, 2], 0.0)
        t_bottom = np.minimum((-amplitude - o[:, 2]) / d[:, 2], limit)
    rows = np.flatnonzero(down & (t_top < t_bottom))
    if rows.size == 0:
        return rows, np.empty(0), np.empty((0, 3))
    found, tr = _first_crossing(waves, o[rows], d[rows], t_top[rows], t_bottom[rows], time_s)
    rows, tr = rows[found], tr[found]
    p = o[rows] + tr[:, None] * d[rows]
    return rows, tr, waves.normal(p[:, 0], p[:, 1], time_s).reshape(-1, 3)


def _gap(waves: WaveField, o: F64, d: F64, t: F64, time_s: float) -> F64:
    """f(t) = height of the ray point above the surface (positive above the water)."""
    p = o + t[:, None] * d
    return np.asarray(p[:, 2] - waves.height(p[:, 0], p[:, 1], time_s))


def _first_crossing(
    waves: WaveField, o: F64, d: F64, t0: F64, t1: F64, time_s: float
) -> tuple[NDArray[np.bool_], F64]:
    """(found, t): the first root of f in [t0, t1] per ray, marched then refined. The march
    goes sample by sample and drops a ray as soon as it is under the surface, so a ray costs
    the samples up to its crossing, not all of them."""
    m, step = t0.size, (t1 - t0) / MARCH_SAMPLES
    a, fa = t0.copy(), _gap(waves, o, d, t0, time_s)
    b, fb = t0.copy(), fa.copy()
    found = fa <= 0.0  # already under water at the top of the bracket: t0
    live = np.flatnonzero(~found)
    for k in range(1, MARCH_SAMPLES + 1):
        if live.size == 0:
            break
        t = t0[live] + k * step[live]
        f = _gap(waves, o[live], d[live], t, time_s)
        under = f <= 0.0
        done = live[under]
        b[done], fb[done], found[done] = t[under], f[under], True
        above = live[~under]
        a[above], fa[above] = t[~under], f[~under]
        live = above
    rows = np.flatnonzero(found)
    t_hit = np.full(m, np.inf)
    t_hit[rows] = _illinois(waves, o[rows], d[rows], a[rows], b[rows], fa[rows], fb[rows], time_s)
    return found, t_hit


def _illinois(
    waves: WaveField, o: F64, d: F64, a: F64, b: F64, fa: F64, fb: F64, time_s: float
) -> F64:
    """Illinois false position on brackets [a, b] with f(a) > 0 >= f(b), all rays at once;
    rays whose estimate is within TOLERANCE_M of the surface drop out of later steps."""
    out = b.copy()
    live = np.arange(b.size)
    for _ in range(REFINE_STEPS):
        span = fa - fb
        c = np.where(span > 0.0, b + fb * (b - a) / np.where(span > 0.0, span, 1.0), b)
        fc = _gap(waves, o[live], d[live], c, time_s)
        out[live] = c
        left = fc > 0.0  # root in [c, b]: a moves to c; halve the kept end's f (Illinois)
        a, fa, fb = np.where(left, c, a), np.where(left, fc, fa * 0.5), np.where(left, fb * 0.5, fb)
        b, fb = np.where(left, b, c), np.where(left, fb, fc)
        todo = np.abs(fc) > TOLERANCE_M
        if not todo.any():
            break
        live, a, b, fa, fb = live[todo], a[todo], b[todo], fa[todo], fb[todo]
    return out
