"""Rotations, one module: quaternions (x, y, z, w, DESIGN.md §2), matrices, yaw, rotation
vectors. Physics, sensors and traffic all turn frames with these, so one convention holds.

Matrices are body-to-map (`v_map = R @ v_body`). The single-quaternion form uses Python
floats (a few microseconds where NumPy's overhead would be tens); the batch forms are the
same operations in the same order, so both give the same bits.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

Array = NDArray[np.float64]


def matrices(q: Array) -> Array:
    """(N, 3, 3) rotations of unit quaternions (N, 4), not normalised again (physics' own)."""
    x, y, z, w = q[:, 0], q[:, 1], q[:, 2], q[:, 3]
    return _stack(x, y, z, w)


def normalised_matrices(q: Array) -> Array | None:
    """(N, 3, 3) rotations of quaternions normalised first (states rounded in transit still
    give proper rotations), or None if any is non-finite or of zero length."""
    x, y, z, w = np.asarray(q, dtype=np.float64).T
    norm = np.sqrt(x * x + y * y + z * z + w * w)
    if not (np.isfinite(norm).all() and (norm >= 1e-9).all()):
        return None
    return _stack(x / norm, y / norm, z / norm, w / norm)


def _stack(x: Array, y: Array, z: Array, w: Array) -> Array:
    """Filled in place: nested np.stack calls cost more than the arithmetic for a few rows."""
    out = np.empty((*np.shape(x), 3, 3))
    out[..., 0, 0], out[..., 0, 1] = 1 - 2 * (y * y + z * z), 2 * (x * y - z * w)
    out[..., 0, 2], out[..., 1, 0] = 2 * (x * z + y * w), 2 * (x * y + z * w)
    out[..., 1, 1], out[..., 1, 2] = 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)
    out[..., 2, 0], out[..., 2, 1] = 2 * (x * z - y * w), 2 * (y * z + x * w)
    out[..., 2, 2] = 1 - 2 * (x * x + y * y)
    return out


def vertical(q: Array, v: Array) -> Array:
    """The map-frame up component of body-frame vectors v (N, 3) turned by q (N, 4): the
    third row of `matrices(q)` times v, without the other eight entries."""
    x, y, z, w = q[:, 0], q[:, 1], q[:, 2], q[:, 3]
    return np.asarray(
        2 * (x * z - y * w) * v[:, 0] + 2 * (y * z + x * w) * v[:, 1]
        + (1 - 2 * (x * x + y * y)) * v[:, 2]
    )  # fmt: skip


def cross(a: Array, b: Array) -> Array:
    """a x b over the last axis, with np.cross's operations (the same bits) but none of its
    axis handling, which costs more than the arithmetic for a few vectors: the one cross
    product of physics and sensors."""
    out = np.empty(np.broadcast_shapes(np.shape(a), np.shape(b)))
    a0, a1, a2 = a[..., 0], a[..., 1], a[..., 2]
    b0, b1, b2 = b[..., 0], b[..., 1], b[..., 2]
    out[..., 0], out[..., 1], out[..., 2] = a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0
    return out


def matrix(q: Sequence[float] | Array) -> Array | None:
    """The rotation of one quaternion, normalised first; None if non-finite or zero."""
    x, y, z, w = (float(v) for v in q)
    norm = math.sqrt(x * x + y * y + z * z + w * w)
    if not (math.isfinite(norm) and norm >= 1e-9):
        return None
    x, y, z, w = x / norm, y / norm, z / norm, w / norm
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


def from_rotvec(rv: Array) -> Array:
    """Unit quaternions (N, 4) of rotation vectors (N, 3), stable near zero angle."""
    theta = np.linalg.norm(rv, axis=1)
    small = theta < 1e-6
    safe = np.where(small, 1.0, theta)
    scale = np.where(small, 0.5 - theta * theta / 48.0, np.sin(0.5 * safe) / safe)
    return np.concatenate([rv * scale[:, None], np.cos(0.5 * theta)[:, None]], axis=1)


def from_yaw(yaw_rad: float) -> tuple[float, float, float, float]:
    """The quaternion of a heading (a turn about z)."""
    half = yaw_rad / 2
    return (0.0, 0.0, math.sin(half), math.cos(half))


def yaw_of_quaternions(q: Array) -> Array:
    """ENU headings (rad, counter-clockwise from east) of quaternions (N, 4)."""
    x, y, z, w = q.T
    return np.arctan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))


def levelling(q: Sequence[float]) -> tuple[float, float, float, float]:
    """The level frame that turns with a body's heading, seen from the body: conj(q), then
    the heading's turn (a stabilised sensor's mount, the radar's), so q and this turn together
    are the heading alone. One quaternion in Python floats: a frame or two a tick, where
    NumPy's overhead was 20 us."""
    x, y, z, w = (float(v) for v in q)
    half = math.atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z)) / 2
    s, c = math.sin(half), math.cos(half)
    out = (-x * c - y * s, x * s - y * c, w * s - z * c, w * c + z * s)  # conj(q) (0, 0, s, c)
    return out if out[3] >= 0.0 else (-out[0], -out[1], -out[2], -out[3])


def wrap(angle: Array) -> Array:
    """Angles (rad) into [-pi, pi): the signed difference between two headings."""
    return np.asarray((angle + np.pi) % (2 * np.pi) - np.pi)


def on_slopes(q: Array, normal: Array) -> Array:
    """Quaternions (N, 4) turned so that a body level under `q` has its z along `normal`
    (N, 3, unit): a roll and pitch given on calm water become ones relative to a sloping
    surface, the heading kept."""
    axis = np.column_stack([-normal[:, 1], normal[:, 0], np.zeros(len(normal))])  # z x n
    size = np.linalg.norm(axis, axis=1)
    unit = axis / np.where(size > 0.0, size, 1.0)[:, None]
    return product(from_rotvec(unit * np.arctan2(size, normal[:, 2])[:, None]), q)


def product(a: Array, b: Array) -> Array:
    """Hamilton products a b of quaternions (N, 4): b's turn, then a's; w >= 0 (the sign
    `quaternion_of_matrix` gives)."""
    ax, ay, az, aw = a.T
    bx, by, bz, bw = b.T
    out = np.column_stack([
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
        aw * bw - ax * bx - ay * by - az * bz,
    ])  # fmt: skip
    return np.where(out[:, 3:] < 0.0, -out, out)


def turn_xy(xy: Array, yaw: Array) -> Array:
    """Horizontal vectors (N, 2) turned by headings (N,): body-frame x, y in map axes (a
    boat's velocity over ground from its surge and sway)."""
    c, s = np.cos(yaw), np.sin(yaw)
    return np.column_stack((c * xy[:, 0] - s * xy[:, 1], s * xy[:, 0] + c * xy[:, 1]))


def yaw_of_matrix(rot: Array) -> float:
    """ENU heading of a body-to-map rotation matrix."""
    return math.atan2(float(rot[1, 0]), float(rot[0, 0]))


def rpy(roll_deg: float, pitch_deg: float, yaw_deg: float) -> Array:
    """Rz(yaw) @ Ry(pitch) @ Rx(roll) of angles in degrees (a mount's turn in its body)."""
    r, p, y = (math.radians(a) for a in (roll_deg, pitch_deg, yaw_deg))
    cr, sr, cp, sp, cy, sy = (f(a) for a in (r, p, y) for f in (math.cos, math.sin))
    rz = np.array([[cy, -sy, 0.0], [sy, cy, 0.0], [0.0, 0.0, 1.0]])
    ry = np.array([[cp, 0.0, sp], [0.0, 1.0, 0.0], [-sp, 0.0, cp]])
    rx = np.array([[1.0, 0.0, 0.0], [0.0, cr, -sr], [0.0, sr, cr]])
    return rz @ ry @ rx


def quaternion_of_matrix(rot: Array) -> tuple[float, float, float, float]:
    """The unit quaternion (x, y, z, w, w >= 0) of a rotation matrix (Shepperd's method:
    the largest of the four candidates is computed first, so no square root goes near 0)."""
    m = np.asarray(rot, dtype=np.float64)
    trace = float(m[0, 0] + m[1, 1] + m[2, 2])
    diag = [float(m[i, i]) for i in range(3)]
    if trace >= max(diag):
        s = 2.0 * math.sqrt(1.0 + trace)
        q = ((m[2, 1] - m[1, 2]) / s, (m[0, 2] - m[2, 0]) / s, (m[1, 0] - m[0, 1]) / s, s / 4)
    else:
        i = diag.index(max(diag))
        j, k = (i + 1) % 3, (i + 2) % 3
        s = 2.0 * math.sqrt(1.0 + m[i, i] - m[j, j] - m[k, k])
        v = [0.0, 0.0, 0.0]
        v[i], v[j], v[k] = s / 4, (m[j, i] + m[i, j]) / s, (m[k, i] + m[i, k]) / s
        q = (v[0], v[1], v[2], (m[k, j] - m[j, k]) / s)
    x, y, z, w = (float(c) for c in q)
    return (-x, -y, -z, -w) if w < 0 else (x, y, z, w)


def from_rpy(roll: float, pitch: float, yaw: float) -> tuple[float, float, float, float]:
    """The quaternion of Rz(yaw) Ry(pitch) Rx(roll); a level body (roll = pitch = 0) gets
    exactly `from_yaw`'s numbers, as every start did before roll and pitch existed."""
    if roll == 0 and pitch == 0:
        return from_yaw(yaw)
    cr, sr, cp, sp = (
        math.cos(roll / 2),
        math.sin(roll / 2),
        math.cos(pitch / 2),
        math.sin(pitch / 2),
    )
    cy, sy = math.cos(yaw / 2), math.sin(yaw / 2)
    return (
        sr * cp * cy - cr * sp * sy,
        cr * sp * cy + sr * cp * sy,
        cr * cp * sy - sr * sp * cy,
        cr * cp * cy + sr * sp * sy,
    )


def to_rotvec(q: Array) -> Array:
    """Rotation vectors (N, 3) of unit quaternions (N, 4), the inverse of `from_rotvec`
    (angle in [0, pi]; a yaw-only quaternion gives (0, 0, yaw) for |yaw| <= pi)."""
    q = np.where(q[:, 3:] < 0, -q, q)
    sin_half = np.linalg.norm(q[:, :3], axis=1)
    theta = 2 * np.arctan2(sin_half, q[:, 3])
    small = sin_half < 1e-12
    scale = np.where(small, 2.0, theta / np.where(small, 1.0, sin_half))
    return q[:, :3] * scale[:, None]
