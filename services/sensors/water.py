"""Ray hits on the water surface z = eta(x, y, t): the same WaveField physics floats on.

Calm water is the plane z = 0: one division per ray. With waves, most rays of a LiDAR scan
or a camera frame are solved on a grid of the surface sampled once per cast
(services/sensors/wave_cast.py); this module's exact march takes the rest: casts of a few
rays (a radar tick), rays that leave the grid (a camera's few rays near the horizon) and
seas whose grid would be too fine to pay.

The exact march: |eta| <= A (the sum of the component amplitudes), so a downward ray can
only cross the surface between the heights z = +A and z = -A. That bracket (cut at the
nearest other hit) is sampled at MARCH_SAMPLES points to find the FIRST sign change of
f(t) = z(t) - eta(x(t), y(t), t_now) (a grazing ray can pass over a trough and meet the next
crest), then refined by Newton steps on the exact slope kept inside the bracket, until the
point is within TOLERANCE_M (0.5 mm) of the surface. Rays pointing up or level never hit
water from above. Eight samples over +-A are no proof of the first crossing: a crest that
pokes through between two samples of a ray grazing it far away is missed (seen on rays
within ~0.2 deg of the horizon beyond ~300 m); the grid's walk finds it (wave_kernel.py).

A ray steeper than the steepest possible surface (slope sum a k) meets it exactly once:
it skips the march, and one evaluation where it crosses z = 0 brackets its root tightly
(the root is within |f| / (its minimum descent rate) of there). Known signs are not
evaluated: at z = +A the ray is above every crest, at z = -A below every trough.

Cost: (downward rays in bracket) x (~6 evaluations for grazing rays: ~4.5 march samples and
2-4 refinements; ~4 for steep ones) of the sum, each one float32 multiply-add and cosine per
wave component along the ray (RaySurface), in blocks of BLOCK rays whose tables stay in
cache: ~0.76 us a ray for 48 components. A few rays cost their NumPy calls rather than their
cosines (a radar tick's ~150 downward rays: ~0.6 ms), so their march samples are taken in
one evaluation and the refinement converges in 2-4 Newton steps (Illinois false position,
which it replaced, took up to 16).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from catabot.world.waves import WaveField
from services.sensors.common import rows_of

F64 = NDArray[np.float64]
MARCH_SAMPLES = 8
MARCH_TOGETHER = 4096  # (ray, sample) pairs evaluated in one call at most
REFINE_STEPS = 16  # a cap: Newton in a bracket takes 2-4
TOLERANCE_M = 5e-4  # vertical distance to the surface at which a ray is done: within 1 mm
TWO_PI = 2.0 * np.pi
BLOCK = 4096  # rays solved together: (rays x components) float32 tables of ~0.8 MB


def calm_hits(o: F64, d: F64, max_range: float) -> F64:
    """Distance along each unit ray to the plane z = 0 from above (inf: none within
    `max_range`); the normal there is +z."""
    dz = np.ascontiguousarray(d[:, 2])
    shared = o.strides[0] == 0  # one origin: a scalar height (a camera's 300 k rays)
    oz = o[0, 2] if shared else o[:, 2]
    with np.errstate(divide="ignore", invalid="ignore"):
        t = -oz / dz
    hit = (dz < -1e-12) & (t <= max_range)
    hit &= (oz >= 0.0) if not shared else bool(oz >= 0.0)
    t[~hit] = np.inf
    return t


def wave_hits(
    waves: WaveField, amplitude: float, o: F64, d: F64, limit: F64, time_s: float
) -> tuple[NDArray[np.intp], F64, F64]:
    """The rays that meet the wave surface before `limit`, their distances and the
    surface's unit normals there (world frame)."""
    rows = np.flatnonzero(d[:, 2] < -1e-12)  # only these can meet the water from above
    oz, dz = np.take(o[:, 2], rows), np.take(d[:, 2], rows)
    t_top = np.maximum((amplitude - oz) / dz, 0.0)
    t_under = (-amplitude - oz) / dz  # where the ray is below every trough
    limit = np.take(limit, rows)
    limited = limit < t_under
    t_bottom = np.where(limited, limit, t_under)
    band = np.flatnonzero(t_top < t_bottom)
    rows, t_top, t_bottom, limited = rows[band], t_top[band], t_bottom[band], limited[band]
    found, t, normal = march_hits(
        waves, rows_of(o, rows), np.take(d, rows, axis=0), (t_top, t_bottom), limited, time_s
    )
    return rows[found], t, normal


def march_hits(
    waves: WaveField,
    o: F64,
    d: F64,
    bracket: tuple[F64, F64],
    limited: NDArray[np.bool_],
    time_s: float,
    over: NDArray[np.bool_] | None = None,
) -> tuple[NDArray[np.intp], F64, F64]:
    """The rays (of o, d) whose first crossing lies in [t0, t1] = `bracket`: their index,
    distance and normal. f(t1) <= 0 is taken as known where t1 is not `limited` (the ray is
    under every trough there) and f(t0) >= 0 where `over` (default: t0 > 0, the ray entering
    the band +-A from above); elsewhere f(t0) is evaluated."""
    t0, t1 = bracket
    n = t0.size
    if n == 0:
        return np.empty(0, np.intp), np.empty(0), np.empty((0, 3))
    over = t0 > 0.0 if over is None else over
    found, tr = np.zeros(n, dtype=bool), np.empty(n)
    normal = np.zeros((n, 3))
    for s in range(0, n, BLOCK):  # a block's phase tables stay in cache
        blk = slice(s, s + BLOCK)
        along = RaySurface(waves, o[blk], d[blk], time_s)
        hit, t = _first_crossing(along, t0[blk], t1[blk], limited[blk], over[blk])
        at = np.flatnonzero(hit)
        found[blk], tr[blk] = hit, t
        normal[s + at] = along.normal(at, t[at])
    return np.flatnonzero(found), tr[found], normal[found]


class RaySurface:
    """f(t) = z - eta(x, y) along each of a set of rays p(t) = o + t d, at one instant.

    Along a ray every component's phase is linear in t: k . o - omega T + phi plus t k . d.
    So each ray keeps its phase at t = 0 (reduced to one turn in float64, then float32;
    one vector for all rays when they share their origin) and its phase rate k . d
    (float32), and an evaluation costs one multiply-add and one float32 cosine per
    component: about half of WaveField.height, which rebuilds the phase from (x, y, t).
    The surface is the same sum (the field's own amplitudes, wavenumbers, directions,
    frequencies and phases); float32 phases up to ~100 rad differ from it by < 1e-5 m.
    """

    def __init__(self, waves: WaveField, o: F64, d: F64, time_s: float) -> None:
        k, theta = waves.wavenumbers_radpm, waves.directions_rad
        kxy = np.stack([k * np.cos(theta), k * np.sin(theta)])  # (2, M)
        shift = waves.phases_rad - waves.frequencies_radps * time_s
        start = o[:1] if o.strides[0] == 0 else o  # a shared origin: one row
        phase = np.dot(start[:, :2], kxy) + shift
        phase -= TWO_PI * np.rint(phase / TWO_PI)  # within half a turn before float32
        self.phase0 = phase.astype(np.float32)  # (1 or n, M)
        self.rate = np.dot(d[:, :2].astype(np.float32), kxy.astype(np.float32))  # rad/m, (n, M)
        self.amp = waves.amplitudes_m.astype(np.float32)
        self.slope = (waves.amplitudes_m * kxy).T.astype(np.float32)  # (M, 2): a kx, a ky
        self.oz, self.dz = np.ascontiguousarray(o[:, 2]), np.ascontiguousarray(d[:, 2])
        # |grad eta| <= sum a k: a ray descending faster than that crosses the surface once
        wave_slope = float(np.sum(waves.amplitudes_m * k)) * np.hypot(d[:, 0], d[:, 1])
        self.steep = -self.dz > wave_slope * (1.0 + 1e-6)
        self.descent = -self.dz - wave_slope  # df/dt <= -descent: > 0 on steep rays

    def gap(self, rows: NDArray[np.intp], t: F64) -> F64:
        """f at distances t (metres) along the rays `rows`: positive above the water."""
        phase = self._phase(rows, t)
        eta = np.dot(np.cos(phase, out=phase), self.amp)
        return np.take(self.oz, rows) + t * np.take(self.dz, rows) - eta

    def gap_slope(self, rows: NDArray[np.intp], t: F64) -> tuple[F64, F64]:
        """f and df/dt at distances t along the rays `rows`: d eta/dt = -sum a (k . d) sin."""
        phase = self._phase(rows, t)
        eta = np.dot(np.cos(phase), self.amp)
        np.sin(phase, out=phase)
        phase *= np.take(self.rate, rows, axis=0)
        dz = np.take(self.dz, rows)
        return np.take(self.oz, rows) + t * dz - eta, dz + np.dot(phase, self.amp)

    def normal(self, rows: NDArray[np.intp], t: F64) -> F64:
        """Unit upward surface normals (n, 3) at distances t along the rays `rows`, from the
        analytic gradient as WaveField.normal: -d(eta)/dx = sum a kx sin(phase)."""
        out = np.ones((rows.size, 3))
        phase = self._phase(rows, t)
        out[:, :2] = np.dot(np.sin(phase, out=phase), self.slope)
        out /= np.linalg.norm(out, axis=1, keepdims=True)
        return out

    def _phase(self, rows: NDArray[np.intp], t: F64) -> NDArray[np.float32]:
        phase = np.take(self.rate, rows, axis=0)
        phase *= t.astype(np.float32)[:, None]
        phase += self.phase0 if self.phase0.shape[0] == 1 else np.take(self.phase0, rows, 0)
        return phase


def _first_crossing(
    surface: RaySurface,
    t0: F64,
    t1: F64,
    limited: NDArray[np.bool_],
    over: NDArray[np.bool_],
) -> tuple[NDArray[np.bool_], F64]:
    """(found, t): the first root of f in [t0, t1] per ray, marched then refined.

    Known signs are not evaluated: where t0 > 0 the ray is at z = +A, over every crest, so
    f(t0) >= 0, and where t1 is not `limited` (cut short by a nearer hit) it is at z = -A,
    so f(t1) <= 0; there z itself stands in for f (the refinement needs only the signs).
    A ray steeper than the steepest possible surface (RaySurface.steep) meets it at most
    once: it goes straight to the refinement. The others are marched sample by sample and
    dropped as soon as they are under the surface, so a ray costs the samples up to its
    crossing, not all of them."""
    m = t0.size
    a, fa = t0.copy(), surface.oz + t0 * surface.dz
    b, fb = t1.copy(), surface.oz + t1 * surface.dz
    inside = np.flatnonzero(~over)  # starting within the wave band: f(t0) unknown
    fa[inside] = surface.gap(inside, t0[inside])
    found = fa <= 0.0  # already under water at the top of the bracket: t0
    b[found], fb[found] = a[found], fa[found]
    steep = surface.steep & ~found
    check = np.flatnonzero(steep & limited)  # one crossing at most: is it before t1?
    fb[check] = surface.gap(check, t1[check])
    found |= steep & (fb <= 0.0)
    _narrow(surface, np.flatnonzero(steep & found), a, fa, b, fb)
    live = np.flatnonzero(~found & ~steep)
    march = _march_all if live.size * MARCH_SAMPLES <= MARCH_TOGETHER else _march_on
    march(surface, live, (t0, t1), (a, fa, b, fb), found)
    rows = np.flatnonzero(found)
    t_hit = np.full(m, np.inf)
    t_hit[rows] = _refine(surface, rows, a[rows], b[rows], fa[rows], fb[rows])
    return found, t_hit


def _march_on(
    surface: RaySurface,
    live: NDArray[np.intp],
    span: tuple[F64, F64],
    bracket: tuple[F64, F64, F64, F64],
    found: NDArray[np.bool_],
) -> None:
    """March the rays `live` sample by sample, each dropped once under the surface (it costs
    the samples up to its crossing), narrowing `bracket` (a, fa, b, fb) in place."""
    t0, t1 = span
    a, fa, b, fb = bracket
    step = (t1 - t0) / MARCH_SAMPLES
    for k in range(1, MARCH_SAMPLES + 1):
        if live.size == 0:
            break
        t = t0[live] + k * step[live]
        f = surface.gap(live, t)
        under = f <= 0.0
        done = live[under]
        b[done], fb[done], found[done] = t[under], f[under], True
        above = live[~under]
        a[above], fa[above] = t[~under], f[~under]
        live = above


def _march_all(
    surface: RaySurface,
    live: NDArray[np.intp],
    span: tuple[F64, F64],
    bracket: tuple[F64, F64, F64, F64],
    found: NDArray[np.bool_],
) -> None:
    """The same march with every sample of every ray in one evaluation: for a few rays (a
    radar tick's) the NumPy calls of eight steps cost more than the extra cosines."""
    if live.size == 0:
        return
    t0, t1 = span
    a, fa, b, fb = bracket
    k = np.arange(1, MARCH_SAMPLES + 1)[:, None]
    t = t0[live] + k * ((t1[live] - t0[live]) / MARCH_SAMPLES)  # (samples, rays)
    f = surface.gap(np.tile(live, MARCH_SAMPLES), t.ravel()).reshape(t.shape)
    under = f <= 0.0
    first = np.argmax(under, axis=0)
    cross = under.any(axis=0)
    cols = np.arange(live.size)
    last = np.where(cross, first - 1, MARCH_SAMPLES - 1)  # the last sample above the surface
    seen = last >= 0
    rows = live[seen]
    a[rows], fa[rows] = t[last[seen], cols[seen]], f[last[seen], cols[seen]]
    hit = live[cross]
    b[hit], fb[hit], found[hit] = t[first[cross], cols[cross]], f[first[cross], cols[cross]], True


def _narrow(surface: RaySurface, rows: NDArray[np.intp], a: F64, fa: F64, b: F64, fb: F64) -> None:
    """Shrink the brackets of steep rays (one root in [a, b]) in place with one evaluation:
    at z = 0, f = -eta there; f falls at least `descent` per metre, so the root lies within
    |f| / descent of it, on the side f's sign gives. The far end gets the value f would
    have if the surface were flat there (the sign is certain, the size a good guess)."""
    if rows.size == 0:
        return
    ra, rb = a[rows], b[rows]
    t = np.clip(-np.take(surface.oz, rows) / np.take(surface.dz, rows), ra, rb)
    f = surface.gap(rows, t)
    fall, sink = np.take(surface.descent, rows), -np.take(surface.dz, rows)
    above = f > 0.0
    reach = np.abs(f) / fall
    far = np.where(above, np.minimum(t + reach, rb), np.maximum(t - reach, ra))
    cut = np.where(above, far < rb, far > ra)  # else the old end (and its value) stays
    guess = f - sink * (far - t)  # sign certain: <= 0 beyond, >= 0 before
    a[rows] = np.where(above, t, np.where(cut, far, ra))
    fa[rows] = np.where(above, f, np.where(cut, guess, fa[rows]))
    b[rows] = np.where(above, np.where(cut, far, rb), t)
    fb[rows] = np.where(above, np.where(cut, guess, fb[rows]), f)


def _refine(surface: RaySurface, rows: NDArray[np.intp], a: F64, b: F64, fa: F64, fb: F64) -> F64:
    """Newton steps with the exact slope on brackets [a, b] with f(a) > 0 >= f(b), all rays at
    once, from the secant point; a step that would leave the bracket halves it instead. Rays
    within TOLERANCE_M of the surface drop out: 2-4 steps (Illinois false position, which
    this replaced, took up to 16 on grazing rays: a radar tick's ~70 rays paid ~25 us a step
    in NumPy calls whatever their number)."""
    out = b.copy()
    live = np.arange(b.size)
    span = fa - fb
    c = np.where(span > 0.0, b + fb * (b - a) / np.where(span > 0.0, span, 1.0), b)
    for _ in range(REFINE_STEPS):
        f, slope = surface.gap_slope(rows[live], c)
        out[live] = c
        todo = np.flatnonzero(np.abs(f) > TOLERANCE_M)
        if todo.size == 0:
            break
        live, c, f, slope = live[todo], c[todo], f[todo], slope[todo]
        a, b = a[todo], b[todo]
        above = f > 0.0
        a, b = np.where(above, c, a), np.where(above, b, c)
        with np.errstate(divide="ignore", invalid="ignore"):
            step = c - f / slope
        inside = (step > a) & (step < b)  # NaN and inf too
        c = np.where(inside, step, 0.5 * (a + b))
    return out
