"""The exact march, compiled: each ray's first crossing of the wave sum, one ray at a time.

Why compiled: in NumPy the march paid its calls, not its cosines. A camera's ~700 rays
beyond its grid took 1.3-1.6 ms in ~20 evaluations of ~15 NumPy calls each (most rays
need 4-6 Newton steps on a grazing bracket, and the stragglers kept every step's calls
alive); a radar tick's ~150 rays ~0.6 ms. Here an evaluation of 48 components costs
~22 ns (~38 with its slope): float32 cosines and sines by polynomial (below), which the
compiler vectorises, where the C library's scalar cosf cost ~170 ns an evaluation.

The algorithm is services/sensors/water.py's (its docstring): the bracket where the ray is
within +-A of z = 0, eight march samples for rays that are not steeper than the steepest
surface, one evaluation at z = 0 for those that are, then Newton steps on the exact slope
kept inside the bracket until |f| <= TOLERANCE_M. Along a ray every component's phase is
linear in t: phase0 + t (k . d), phase0 = k . o - omega T + phi reduced to one turn in
float64, then float32 (float32 phases up to ~100 rad differ from the field by < 1e-5 m).
"""

from __future__ import annotations

import functools
import math
from typing import Any

import numpy as np
from numpy.typing import NDArray

from services.sensors.wave_bounds import F64, compiled, compiled_inline, compiled_sum, jit_marked

F32 = NDArray[np.float32]
R32 = np.float32  # one float32 number: the sums stay in float32, as NumPy's did
Sea = tuple[F64, F32, F32, F32, float, float]  # see sea_tables
Bracket = tuple[float, float, float, float]  # a, f(a), b, f(b)
Tables = tuple[F32, F32, F32]  # a ray's phases at t = 0, phase rates, the amplitudes
Ray = tuple[float, float, float]  # oz, dz, the steepest surface's rise along the ray
MARCH_SAMPLES = 8
REFINE_STEPS = 16  # a cap: Newton in a bracket takes 2-6
TOLERANCE_M = 5e-4  # vertical distance to the surface at which a ray is done: within 1 mm
# 2 pi in two parts (Cody-Waite: n * TURN_HI is exact), though reordering sums may fold them:
# then the reduction errs by ~n ulp of 2 pi, less than a float32 phase's own rounding
TURN_HI = np.float32(6.28125)
TURN_LO = np.float32(2.0 * math.pi - 6.28125)
PER_TURN = np.float32(1.0 / (2.0 * math.pi))
# Taylor coefficients of cos and sin in y^2 up to y^19, for |y| <= pi (truncation < 4e-9,
# under float32 rounding)
COS = tuple(np.float32((-1) ** n / math.factorial(2 * n)) for n in range(10))
SIN = tuple(np.float32((-1) ** n / math.factorial(2 * n + 1)) for n in range(10))


def sea_tables(k: F64, theta: F64, amplitudes: F64) -> Sea:
    """What the kernel reads of a sea, whatever the instant: the wave vectors (2, M) in
    float64 (phases at the origins) and float32 (phase rates), the amplitudes, their slopes
    a k (2, M), the sum of the amplitudes (the band) and of a k (the steepest surface). The
    instant comes with each call: the phases at the map's origin, phi - omega T."""
    kxy = np.stack([k * np.cos(theta), k * np.sin(theta)])
    slopes = (amplitudes * kxy).astype(np.float32)
    amplitude, steepest = float(np.sum(amplitudes)), float(np.sum(amplitudes * k))
    k32, a32 = kxy.astype(np.float32), amplitudes.astype(np.float32)
    return kxy, k32, a32, slopes, amplitude, steepest


@compiled_inline
def _turned(x: R32) -> R32:
    """x reduced to [-pi, pi] in float32."""
    n = np.floor(x * PER_TURN + np.float32(0.5))
    return (x - n * TURN_HI) - n * TURN_LO


@compiled_inline
def _cos(x: R32) -> R32:
    """cos x by its Taylor polynomial on [-pi, pi]: the compiler vectorises it."""
    y = _turned(x)
    y2, c = y * y, COS
    return c[0] + y2 * (c[1] + y2 * (c[2] + y2 * (c[3] + y2 * (c[4] + y2 * (c[5] + y2 * (
        c[6] + y2 * (c[7] + y2 * (c[8] + y2 * c[9]))))))))  # fmt: skip


@compiled_inline
def _sin(x: R32) -> R32:
    y = _turned(x)
    y2, s = y * y, SIN
    return y * (s[0] + y2 * (s[1] + y2 * (s[2] + y2 * (s[3] + y2 * (s[4] + y2 * (s[5] + y2 * (
        s[6] + y2 * (s[7] + y2 * (s[8] + y2 * s[9])))))))))  # fmt: skip


@compiled_sum
def _eta(phase0: F32, rate: F32, amp: F32, t: float) -> float:
    """The surface's height at t along the ray."""
    tf = np.float32(t)
    eta = np.float32(0.0)
    for m in range(amp.shape[0]):
        eta += amp[m] * _cos(phase0[m] + tf * rate[m])
    return float(eta)


@compiled_sum
def _eta_fall(phase0: F32, rate: F32, amp: F32, t: float) -> tuple[float, float]:
    """The height at t along the ray and how fast it falls along the ray (-d eta/dt =
    sum a (k . d) sin)."""
    tf = np.float32(t)
    eta, fall = np.float32(0.0), np.float32(0.0)
    for m in range(amp.shape[0]):
        phase = phase0[m] + tf * rate[m]
        eta += amp[m] * _cos(phase)
        fall += amp[m] * rate[m] * _sin(phase)
    return float(eta), float(fall)


@compiled_sum
def _slope(phase0: F32, rate: F32, slopes: F32, t: float) -> tuple[float, float]:
    """-d eta/dx, -d eta/dy at t along the ray: sum a k sin(phase)."""
    tf = np.float32(t)
    gx, gy = np.float32(0.0), np.float32(0.0)
    for m in range(rate.shape[0]):
        s = _sin(phase0[m] + tf * rate[m])
        gx += slopes[0, m] * s
        gy += slopes[1, m] * s
    return float(gx), float(gy)


@compiled_inline
def _gap(tables: Tables, ray: Ray, t: float) -> float:
    """f = z - eta at t along the ray: positive above the water."""
    return ray[0] + t * ray[1] - _eta(*tables, t)


@compiled_inline
def _phases(kxy: F64, shift: F64, x: float, y: float, out: F32) -> None:
    """Each component's phase at (x, y), reduced to within half a turn before float32."""
    for m in range(out.shape[0]):
        p = x * kxy[0, m] + y * kxy[1, m] + shift[m]
        out[m] = np.float32(p - 2.0 * math.pi * np.rint(p / (2.0 * math.pi)))


@compiled_inline
def _rates(k32: F32, dx: float, dy: float, out: F32) -> None:
    """Each component's phase rate along the ray, k . d (rad/m)."""
    fx, fy = np.float32(dx), np.float32(dy)
    for m in range(out.shape[0]):
        out[m] = fx * k32[0, m] + fy * k32[1, m]


@compiled_inline
def _band(oz: float, dz: float, limit: float, amplitude: float) -> tuple[float, float, bool]:
    """Where a downward ray is within +-A of z = 0: from z = +A (or its origin) to z = -A or
    `limit`, whichever is first, and whether `limit` cut it (lo >= hi: no bracket)."""
    if not dz < -1e-12:
        return math.inf, -math.inf, False
    under = (-amplitude - oz) / dz
    limited = limit < under
    return max((amplitude - oz) / dz, 0.0), limit if limited else under, limited


@compiled
def march_pass(
    sea: Sea, shift: F64, o: F64, d: F64, limit: F64, t_out: F64, normal_out: F64
) -> None:
    """Each ray's first crossing before `limit` into t_out (inf: none) and the surface's
    upward unit normal there into normal_out, the phases at the map's origin being `shift`.
    Origins o: (1, 3) shared or (n, 3)."""
    kxy, k32, amp, slopes, amplitude, steepest = sea
    phase0, rate = np.empty(amp.shape[0], np.float32), np.empty(amp.shape[0], np.float32)
    shared = o.shape[0] == 1
    if shared:
        _phases(kxy, shift, o[0, 0], o[0, 1], phase0)
    for r in range(d.shape[0]):
        t_out[r] = math.inf
        k = 0 if shared else r
        t0, t1, limited = _band(o[k, 2], d[r, 2], limit[r], amplitude)
        if not t0 < t1:
            continue
        if not shared:
            _phases(kxy, shift, o[k, 0], o[k, 1], phase0)
        _rates(k32, d[r, 0], d[r, 1], rate)
        steep = steepest * math.hypot(d[r, 0], d[r, 1])  # the steepest surface along the ray
        ray = (o[k, 2], d[r, 2], steep)
        t = _crossing((phase0, rate, amp), ray, (t0, t1), limited)
        t_out[r] = t
        if t < math.inf:
            gx, gy = _slope(phase0, rate, slopes, t)
            scale = 1.0 / math.sqrt(1.0 + gx * gx + gy * gy)
            normal_out[r, 0], normal_out[r, 1], normal_out[r, 2] = gx * scale, gy * scale, scale


@compiled
def _crossing(tables: Tables, ray: Ray, span: tuple[float, float], limited: bool) -> float:
    """The first root of f = z - eta in [t0, t1] = span (inf: none). Known signs are not
    evaluated: where t0 > 0 the ray is at z = +A, over every crest; where t1 is not
    `limited` it is at z = -A, under every trough."""
    (oz, dz, steep), (t0, t1) = ray, span
    fa = oz + t0 * dz
    if not t0 > 0.0:  # the origin is within the band: f(t0) unknown
        fa -= _eta(*tables, t0)
    if fa <= 0.0:
        return t0  # under water at the top of the bracket
    bracket = (t0, fa, t1, oz + t1 * dz)
    if -dz > steep * (1.0 + 1e-6):  # steeper than the surface: one crossing at most
        if limited:
            fb = _gap(tables, ray, t1)
            if fb > 0.0:
                return math.inf
            bracket = (t0, fa, t1, fb)
        bracket = _narrow(tables, ray, bracket)
    else:
        bracket = _march(tables, ray, bracket)
        if bracket[3] > 0.0:
            return math.inf
    return _refine(tables, ray, bracket)


@compiled
def _march(tables: Tables, ray: Ray, bracket: Bracket) -> Bracket:
    """MARCH_SAMPLES samples from t0 to t1 up to the first under the surface: (the last
    above, its f, the first under, its f); f(b) > 0 where none is."""
    a, fa, t1, _ = bracket
    t0, step = a, (t1 - a) / MARCH_SAMPLES
    for k in range(1, MARCH_SAMPLES + 1):
        t = t0 + k * step
        f = _gap(tables, ray, t)
        if f <= 0.0:
            return a, fa, t, f
        a, fa = t, f
    return a, fa, t1, 1.0


@compiled
def _narrow(tables: Tables, ray: Ray, bracket: Bracket) -> Bracket:
    """A steep ray's bracket (one root) shrunk with one evaluation at z = 0: f falls at
    least (-dz - steep) a metre, so the root lies within |f| / that of it, on the side f's
    sign gives. The far end gets the value f would have if the surface were flat there."""
    (oz, dz, steep), (a, fa, b, fb) = ray, bracket
    t = min(max(-oz / dz, a), b)
    f = _gap(tables, ray, t)
    reach = abs(f) / (-dz - steep)
    if f > 0.0:
        far = min(t + reach, b)
        return (t, f, far, f + dz * (far - t)) if far < b else (t, f, b, fb)
    far = max(t - reach, a)
    return (far, f + dz * (far - t), t, f) if far > a else (a, fa, t, f)


@compiled
def _refine(tables: Tables, ray: Ray, bracket: Bracket) -> float:
    """Newton steps with the exact slope from the secant point of [a, b] (f(a) > 0 >= f(b));
    a step that would leave the bracket halves it instead. Done within TOLERANCE_M."""
    (oz, dz, _), (a, fa, b, fb) = ray, bracket
    span = fa - fb
    c = b + fb * (b - a) / span if span > 0.0 else b
    last = c
    for _ in range(REFINE_STEPS):
        eta, fall = _eta_fall(*tables, c)
        f, last = oz + c * dz - eta, c
        if abs(f) <= TOLERANCE_M:
            break
        if f > 0.0:
            a = c
        else:
            b = c
        step = c - f / (dz + fall)
        c = step if a < step < b else 0.5 * (a + b)
    return last


@functools.cache
def marcher() -> Any:
    """The compiled march_pass (numba loaded, the module's kernels compiled or read from the
    cache, at the first call)."""
    return jit_marked(globals())["march_pass"]
