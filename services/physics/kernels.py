"""The force model's per-body loops, compiled (numba): buoyancy columns, added mass, the
velocity controllers and their measurement, the thrust table, in waves the surface's
expansions at the columns, and the frames (poses from DART's vectors, wrenches and twists
turned between world and body).

Why: written as NumPy array passes these were ≈60 calls a step, each a full pass over an
(N, C) or (N, 6) temporary. In Table II's 100-boat cell the physics service's CPU a tick fell
from 1.11-1.15 to 0.89-0.90 ms, and with the ego alone from 0.43-0.49 to 0.34-0.36 ms
(README, Performance). One loop per body keeps every value in registers.
Each kernel does the arithmetic of the NumPy form it replaced, in the same order within a
row; sums over a body's columns run left to right (NumPy summed pairwise), so results agree
to rounding, not bit for bit. Comparisons are written so that a NaN stays NaN (as np.clip
and np.maximum keep it): a diverging body is still named by physics' finite checks.
Compiled on first use and cached on disk (`make setup` compiles them, see `warm_up`).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, TypeVar, cast

import numba
import numpy as np
from numpy.typing import NDArray

Array = NDArray[np.float64]
F = TypeVar("F", bound=Callable[..., Any])


def jit(fn: F) -> F:
    """Compiled, cached on disk, the GIL released, NumPy's floating-point errors (inf, NaN
    rather than an exception): typed for mypy as the Python function it compiles."""
    return cast(F, numba.njit(cache=True, nogil=True, error_model="numpy")(fn))


@jit
def _clamp(x: float, lo: float, hi: float) -> float:
    """np.clip for one value: NaN stays NaN."""
    if x < lo:
        return lo
    if x > hi:
        return hi
    return x


@jit
def buoyancy(
    rot: Array, pos: Array, columns: tuple[Array, Array, Array], eta: Array, rho_g: float
) -> Array:
    """Body-frame buoyancy wrench (N, 6) of every body's columns: hydro.buoyancy_wrench's
    law. columns: bottoms (N, 3, C) in the body frame, heights and volumes (N, C); eta (N, C)
    the water height at each column."""
    bottom, height, volume = columns
    n, c_max = height.shape
    out = np.empty((n, 6))
    for i in range(n):
        r20, r21, cos_tilt, z0 = rot[i, 2, 0], rot[i, 2, 1], rot[i, 2, 2], pos[i, 2]
        total, m0, m1, m2 = 0.0, 0.0, 0.0, 0.0
        for c in range(c_max):
            bx, by, bz, h = bottom[i, 0, c], bottom[i, 1, c], bottom[i, 2, c], height[i, c]
            rise = h * cos_tilt  # signed world-vertical extent
            low = (0.0 if rise > 0.0 else rise) + (r20 * bx + r21 * by + cos_tilt * bz + z0)
            span = abs(rise)
            frac = _clamp((eta[i, c] - low) / (1e-12 if span < 1e-12 else span), 0.0, 1.0)
            force = volume[i, c] * frac * rho_g
            along = frac * h * 0.5  # submerged centroid along body z, from the lower end
            if cos_tilt < 0.0:
                along = h - along
            total += force
            m0 += bx * force
            m1 += by * force
            m2 += bz * force + force * along
        u0, u1, u2 = r20, r21, cos_tilt  # world +z in the body frame
        out[i, 0], out[i, 1], out[i, 2] = total * u0, total * u1, total * u2
        out[i, 3], out[i, 4], out[i, 5] = m1 * u2 - m2 * u1, m2 * u0 - m0 * u2, m0 * u1 - m1 * u0
    return out


@jit
def _cross_into(out: Array, a: Array, b: Array) -> None:
    out[0] = a[1] * b[2] - a[2] * b[1]
    out[1] = a[2] * b[0] - a[0] * b[2]
    out[2] = a[0] * b[1] - a[1] * b[0]


@jit
def _matvec_into(out: Array, m: Array, x: Array) -> None:
    """out = m @ x for a small square m, summed left to right (numba's @ needs scipy)."""
    for r in range(m.shape[0]):
        acc = 0.0
        for k in range(m.shape[1]):
            acc += m[r, k] * x[k]
        out[r] = acc


@jit
def added_mass(
    tables: tuple[Array, Array, Array, Array, Array, Array],
    z_b: Array,
    nu: Array,
    nu_c: Array,
    other: Array,
    gravity: float,
) -> Array:
    """tau_A (N, 6) per row: added_mass.AddedMass's solve (its docstring has the model).
    tables: M_RB (N, 6, 6), the augmented inverse (N, 6, 6), diag A (N, 6), its manoeuvring
    part (N, 6), mass (N, 1), COG (N, 3)."""
    m_rb, inverse, diag, coriolis_diag, mass, cog = tables
    out = np.empty((len(nu), 6))
    p, total, nu_dot = np.empty(6), np.empty(6), np.empty(6)
    c = np.empty((5, 3))  # w x p1, v x p1, w x p2, r_g x z_b, w x nu_c
    for i in range(len(nu)):
        w, v = nu[i, 3:], nu[i, :3]
        _matvec_into(p, m_rb[i], nu[i])  # rigid-body momenta [p1, p2]
        u_r, v_r, w_r = v[0] - nu_c[i, 0], v[1] - nu_c[i, 1], v[2] - nu_c[i, 2]
        a1, a2, a6 = coriolis_diag[i, 0], coriolis_diag[i, 1], coriolis_diag[i, 5]
        m1, m2, m6 = a1 * u_r, a2 * v_r, a6 * w[2]  # added-mass momenta (manoeuvring)
        ca = (-w[2] * m2, w[2] * m1, w[0] * m2 - w[1] * m1,
              w[1] * m6 - w_r * m2, w_r * m1 - w[0] * m6, u_r * m2 - v_r * m1)  # fmt: skip
        _cross_into(c[0], w, p[:3])
        _cross_into(c[1], v, p[:3])
        _cross_into(c[2], w, p[3:])
        _cross_into(c[3], cog[i], z_b[i])
        _cross_into(c[4], w, nu_c[i])
        weight = -gravity * mass[i, 0]
        for k in range(3):
            turning = diag[i, k] * c[4, k]  # A_lin (w x nu_c): the current turning with the hull
            total[k] = other[i, k] - ca[k] + (weight * z_b[i, k] - c[0, k] - turning)
            total[3 + k] = other[i, 3 + k] - ca[3 + k] + (weight * c[3, k] - c[1, k] - c[2, k])
        _matvec_into(nu_dot, inverse[i], total)
        for k in range(6):
            out[i, k] = -diag[i, k] * nu_dot[k] - ca[k]
        for k in range(3):
            out[i, k] -= diag[i, k] * c[4, k]
    return out


@jit
def _largest_scale(base: Array, step: Array, rev: Array, fwd: Array) -> float:
    """Largest s in [0, 1] with -rev <= base + s * step <= fwd for every thruster (base
    inside)."""
    s = 1.0
    for t in range(len(step)):
        if step[t] > 0.0:
            s = min(s, (fwd[t] - base[t]) / step[t])
        elif step[t] < 0.0:
            s = min(s, (-rev[t] - base[t]) / step[t])
    return _clamp(s, 0.0, 1.0)


@jit
def twist_commands(
    tables: tuple[Array, Array, Array, Array, Array],
    gains: tuple[float, float, float],
    integral: Array,
    rows: NDArray[np.intp],
    setpoints: tuple[Array, Array],
) -> Array:
    """Normalised thruster commands (len(rows), T) for vessels `rows`: control.TwistController's
    law (feed-forward, PI with conditional integration, yaw-first allocation). tables: damping
    (N, 2, 2), inertia (N, 2), allocation pseudo-inverse (N, T, 2), reverse and forward limits
    (N, T); gains: dt, kp, ki; `integral` (N, 2) is updated in place."""
    damp, inertia, pinv, rev, fwd = tables
    dt, kp, ki = gains
    target, measured = setpoints
    out = np.zeros((len(rows), pinv.shape[1]))
    trial, wrench = np.empty(2), np.empty(2)
    zero, yaw, surge = np.zeros(pinv.shape[1]), np.empty(pinv.shape[1]), np.empty(pinv.shape[1])
    for k in range(len(rows)):
        i = rows[k]
        for a in range(2):
            goal, error = target[k, a], target[k, a] - measured[k, a]
            feed = damp[i, a, 0] * goal + damp[i, a, 1] * goal * abs(goal)
            trial[a] = _clamp(integral[i, a] + error * dt, -5.0, 5.0)
            wrench[a] = feed + inertia[i, a] * (kp * error + ki * trial[a])
        for t in range(len(yaw)):
            yaw[t], surge[t] = pinv[i, t, 1] * wrench[1], pinv[i, t, 0] * wrench[0]
        s_yaw = _largest_scale(zero, yaw, rev[i], fwd[i])
        yaw *= s_yaw
        s_surge = _largest_scale(yaw, surge, rev[i], fwd[i])
        if s_yaw >= 1.0 and s_surge >= 1.0:
            integral[i] = trial
        for t in range(len(yaw)):
            force = yaw[t] + s_surge * surge[t]
            limit = fwd[i, t] if force >= 0.0 else rev[i, t]
            out[k, t] = _clamp(force / max(limit, 1e-9), -1.0, 1.0)
    return out


@jit
def expansion_heights(rot: Array, bottom: Array, coef: NDArray[np.float32]) -> Array:
    """eta (N, C) at every body's columns from one Taylor expansion about each body's origin:
    surface.horner's polynomial in float32, of the columns' offsets from the origin (bottom
    (N, 3, C), body frame, turned by rot). coef (N, n + 1, n + 1): c[p, q] of dx^p dy^q (zero
    where p + q > n). Each Horner step runs across a body's columns at once: one column at a
    time, its chain of dependent multiply-adds took 7x longer (73 vs 10 us for 101 bodies)."""
    n_bodies, _, c_max = bottom.shape
    order = coef.shape[1] - 1
    out = np.empty((n_bodies, c_max))
    dx, dy = np.empty(c_max, np.float32), np.empty(c_max, np.float32)
    eta, inner = np.empty(c_max, np.float32), np.empty(c_max, np.float32)
    for i in range(n_bodies):
        r, c = rot[i], coef[i]
        for k in range(c_max):
            bx, by, bz = bottom[i, 0, k], bottom[i, 1, k], bottom[i, 2, k]
            dx[k] = r[0, 0] * bx + r[0, 1] * by + r[0, 2] * bz
            dy[k] = r[1, 0] * bx + r[1, 1] * by + r[1, 2] * bz
        eta[:] = 0.0
        for p in range(order, -1, -1):
            inner[:] = 0.0
            for q in range(order - p, -1, -1):
                term = c[p, q]
                for k in range(c_max):
                    inner[k] = inner[k] * dy[k] + term
            for k in range(c_max):
                eta[k] = eta[k] * dx[k] + inner[k]
        for k in range(c_max):
            out[i, k] = eta[k]
    return out


@jit
def surge_and_yaw_rate(rot: Array, vel_w: Array, rows: NDArray[np.intp]) -> Array:
    """(len(rows), 2): body-frame surge u (body x . linear velocity) and yaw rate r (body z .
    angular velocity) of bodies `rows`; vel_w (N, 6) is [angular, linear], world frame."""
    out = np.empty((len(rows), 2))
    for k in range(len(rows)):
        i = rows[k]
        out[k, 0] = (
            rot[i, 0, 0] * vel_w[i, 3] + rot[i, 1, 0] * vel_w[i, 4] + rot[i, 2, 0] * vel_w[i, 5]
        )
        out[k, 1] = (
            rot[i, 0, 2] * vel_w[i, 0] + rot[i, 1, 2] * vel_w[i, 1] + rot[i, 2, 2] * vel_w[i, 2]
        )
    return out


@jit
def store_commands(
    table: Array, count: NDArray[np.intp], rows: NDArray[np.intp], commands: Array
) -> int:
    """Commands (len(rows), >= 1) for vessels `rows` into the thruster table (N, T), each
    clamped to [-1, 1], columns past a vessel's `count` thrusters zero; nothing is stored
    if a value a vessel uses is not finite: returns that row's index, else -1."""
    width = min(commands.shape[1], table.shape[1])
    for k in range(len(rows)):
        for t in range(min(width, count[rows[k]])):
            if not np.isfinite(commands[k, t]):
                return k
    for k in range(len(rows)):
        i = rows[k]
        for t in range(table.shape[1]):
            table[i, t] = _clamp(commands[k, t], -1.0, 1.0) if t < min(width, count[i]) else 0.0
    return -1


@jit
def poses(q: Array) -> tuple[Array, Array]:
    """Unit quaternions (N, 4) and rotations (N, 3, 3) of DART's generalized positions (N, 6),
    rotation vector first: rotations.from_rotvec then rotations.matrices, the same operations
    in the same order (the same bits, tests check it) in one pass instead of ≈25 NumPy calls
    (≈30 µs a step even for one body)."""
    n = q.shape[0]
    quat, rot = np.empty((n, 4)), np.empty((n, 3, 3))
    for i in range(n):
        a, b, c = q[i, 0], q[i, 1], q[i, 2]
        theta = np.sqrt(a * a + b * b + c * c)
        scale = 0.5 - theta * theta / 48.0 if theta < 1e-6 else np.sin(0.5 * theta) / theta
        x, y, z, w = a * scale, b * scale, c * scale, np.cos(0.5 * theta)
        quat[i, 0], quat[i, 1], quat[i, 2], quat[i, 3] = x, y, z, w
        rot[i, 0, 0], rot[i, 0, 1] = 1 - 2 * (y * y + z * z), 2 * (x * y - z * w)
        rot[i, 0, 2], rot[i, 1, 0] = 2 * (x * z + y * w), 2 * (x * y + z * w)
        rot[i, 1, 1], rot[i, 1, 2] = 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)
        rot[i, 2, 0], rot[i, 2, 1] = 2 * (x * z - y * w), 2 * (y * z + x * w)
        rot[i, 2, 2] = 1 - 2 * (x * x + y * y)
    return quat, rot


@jit
def _turn_into(out: Array, k: int, rot: Array, i: int, v: Array, j: int, inverse: bool) -> None:
    """out[i, k:k+3] = R_i v[i, j:j+3], or R_i^T v[i, j:j+3]."""
    for r in range(3):
        if inverse:
            m0, m1, m2 = rot[i, 0, r], rot[i, 1, r], rot[i, 2, r]
        else:
            m0, m1, m2 = rot[i, r, 0], rot[i, r, 1], rot[i, r, 2]
        out[i, k + r] = m0 * v[i, j] + m1 * v[i, j + 1] + m2 * v[i, j + 2]


@jit
def halves_turned(rot: Array, six: Array, inverse: bool) -> Array:
    """(N, 6) rows [R a, R b] (inverse: R^T) of rows [b, a]: the two frame changes of a
    step, which also swap the halves (DART's [M, F] and [w, v] against Fossen's [F, M] and
    [v, w])."""
    out = np.empty((rot.shape[0], 6))
    for i in range(rot.shape[0]):
        _turn_into(out, 0, rot, i, six, 3, inverse)
        _turn_into(out, 3, rot, i, six, 0, inverse)
    return out


def to_generalized(rot: Array, wrench_b: Array) -> Array:
    """Body-frame [F, M] (N, 6) about the origin -> DART's world-frame [M, F] generalized
    forces."""
    return halves_turned(rot, wrench_b, False)


def body_twist(rot: Array, vel_w: Array) -> Array:
    """World-frame [angular, linear] velocities (N, 6) -> body-frame nu = [v, w] (Fossen)."""
    return halves_turned(rot, vel_w, True)


@jit
def to_body(rot: Array, vec_w: Array) -> Array:
    """R^T v of every row: world-frame vectors (N, 3) in each body's frame."""
    out = np.empty((rot.shape[0], 3))
    for i in range(rot.shape[0]):
        _turn_into(out, 0, rot, i, vec_w, 0, True)
    return out


def warm_up() -> None:
    """Load every kernel (compiled, or from the disk cache) on the argument types physics
    passes, so that no step pays it: PhysicsWorld calls this as it is built, and `make setup`
    and the Dockerfile fill the cache."""
    rot, zeros = np.eye(3)[None], np.zeros((1, 6))
    buoyancy(rot, np.zeros((1, 3)), (np.zeros((1, 3, 1)), np.ones((1, 1)), np.ones((1, 1))),
             np.zeros((1, 1)), 1.0)  # fmt: skip
    tables = (np.eye(6)[None], np.eye(6)[None], zeros, zeros, np.ones((1, 1)), np.zeros((1, 3)))
    added_mass(tables, np.zeros((1, 3)), zeros, np.zeros((1, 3)), zeros, 9.81)
    one = np.ones((1, 1))
    controller = (np.zeros((1, 2, 2)), np.ones((1, 2)), np.zeros((1, 1, 2)), one, one)
    rows, setpoints = np.zeros(1, np.intp), (np.zeros((1, 2)), np.zeros((1, 2)))
    twist_commands(controller, (0.01, 2.0, 0.5), np.zeros((1, 2)), rows, setpoints)
    surge_and_yaw_rate(rot, np.zeros((1, 6)), rows)
    expansion_heights(rot, np.zeros((1, 3, 1)), np.zeros((1, 4, 4), np.float32))
    store_commands(np.zeros((1, 2)), np.ones(1, np.intp), rows, np.zeros((1, 2)))
    poses(zeros)
    to_generalized(rot, zeros)
    body_twist(rot, zeros)  # the same compiled kernel: one type, both flags
    to_body(rot, np.zeros((1, 3)))
