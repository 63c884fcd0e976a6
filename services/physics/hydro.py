"""Hydrostatic and hydrodynamic forces for all vessels at once: NumPy over the vessels, the
per-column and per-thruster loops compiled (kernels.py).

Every per-vessel quantity is stored padded to a common width: columns as (N, C) arrays,
thrusters as (N, T). Padding entries have zero area / zero force, so they contribute nothing
and the hot path needs no Python loop over vessels. Wrenches are 6-vectors in Fossen order
[X, Y, Z, K, M, N] (force then moment), in the body frame (FLU), about the body origin.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Protocol, runtime_checkable

import numpy as np
from numpy.typing import NDArray

from catabot.config.vessel import Hull, Thruster, VesselModel
from services.physics import kernels

Array = NDArray[np.float64]
WaterHeight = Callable[[Array, Array, float], Array]


@runtime_checkable
class ColumnSurface(Protocol):
    """A WaterHeight that also gives eta at body-frame columns (N, 3, C) of bodies turned
    by rot (N, 3, 3), placed where it was sampled: no world-frame copy of the columns."""

    def __call__(self, x: Array, y: Array, time_s: float) -> Array: ...

    def at_columns(self, rot: Array, bottom_m: Array) -> Array: ...


def column_surface(surface: WaterHeight) -> ColumnSurface | None:
    """`surface` if it evaluates columns itself: an attribute lookup, where isinstance on a
    runtime-checkable Protocol walked its members (≈50 µs, twice a step in waves)."""
    return surface if callable(getattr(surface, "at_columns", None)) else None  # type: ignore[return-value]


def water_height(x: Array, y: Array, time_s: float = 0.0) -> Array:
    """Height of the water surface at world points (x, y): calm water at z = 0.

    The hook where waves plug in later: any function with this signature, taking arrays of
    any shape and returning heights of that shape (or broadcastable to it). Calm water
    returns a read-only broadcast view, so it allocates nothing.
    """
    del y, time_s
    return np.broadcast_to(np.float64(0.0), np.shape(x))


# --- buoyancy columns -------------------------------------------------------------------


class Columns:
    """Vertical buoyancy columns of every vessel, padded to (N, C).

    bottom_m: column bottom points in the body frame, stored (N, 3, C) so that one batched
    matmul moves them all (to sample a wavy surface under them); height_m: extent along body
    z; area_m2: horizontal cross-section (0 for padding). The buffers are reused every step:
    fresh arrays of this size cost more in page faults than the arithmetic itself. Not
    thread-safe, by design (one world).
    """

    def __init__(self, bottom_m: Array, height_m: Array, area_m2: Array) -> None:
        self.bottom_m = np.ascontiguousarray(np.asarray(bottom_m).transpose(0, 2, 1))
        self.height_m = np.ascontiguousarray(height_m, dtype=np.float64)
        self.area_m2 = np.ascontiguousarray(area_m2, dtype=np.float64)
        self.volume_m3 = self.height_m * self.area_m2
        self.calm = np.zeros_like(self.height_m)  # the water height at every column, calm
        self._world = np.empty(self.bottom_m.shape)

    def take(self, rows: NDArray[np.intp]) -> Columns:
        """The columns of vessels `rows`, with buffers of their own."""
        return Columns(
            self.bottom_m[rows].transpose(0, 2, 1), self.height_m[rows], self.area_m2[rows]
        )


def hull_columns(hull: Hull) -> tuple[Array, Array, Array]:
    """Discretise one hull into columns: (bottom points (K, 3), heights (K,), areas (K,)).

    A box column spans the full hull height; its columns stand at Gauss-Legendre points
    along and across (`_gauss`). A cylinder (axis along body x) is cut into even strips
    across its diameter; each strip's height is its mean chord (strip area / strip width),
    so the columns hold exactly the cylinder's volume and follow its circular bottom closely.
    """
    n_x, n_y = hull.columns_along, hull.across
    cx, cy, cz = hull.center_m
    xs, wx = _gauss(n_x, hull.length_m)
    if hull.shape == "box":
        assert hull.height_m is not None
        ys, wy = _gauss(n_y, hull.beam_m)
        heights = np.full(n_y, hull.height_m)
    else:
        dy, r = hull.beam_m / n_y, hull.beam_m / 2
        e = np.clip(-r + dy * np.arange(n_y + 1), -r, r)
        ys, wy = (e[:-1] + e[1:]) / 2, np.full(n_y, dy)
        primitive = e * np.sqrt(np.maximum(r * r - e * e, 0.0)) + r * r * np.arcsin(e / r)
        heights = np.diff(primitive) / dy
    gx, gi = np.meshgrid(np.arange(n_x), np.arange(n_y), indexing="ij")
    h = heights[gi].ravel()
    bottom = np.stack([cx + xs[gx].ravel(), cy + ys[gi].ravel(), cz - h / 2], axis=1)
    return bottom, h, (wx[gx] * wy[gi]).ravel()


def _gauss(n: int, length_m: float) -> tuple[Array, Array]:
    """n points over a length centred on 0 and the width each stands for: Gauss-Legendre,
    so the waterplane's area and its first and second moments are exact for any n (even
    spacing gives the second moment short by 1/n^2: two columns across a box had 3/4 of
    its roll stiffness, and the monohull rolled 21% slower than its GM says)."""
    t, w = np.polynomial.legendre.leggauss(n)
    return t * length_m / 2, w * length_m / 2


def build_columns(models: Sequence[VesselModel]) -> Columns:
    """Columns of all vessels, padded to the largest count (set-up time only)."""
    per_vessel = []
    for model in models:
        parts = [hull_columns(h) for h in model.hulls]
        per_vessel.append(tuple(np.concatenate(p) for p in zip(*parts, strict=True)))
    c_max = max(len(h) for _, h, _ in per_vessel)
    n = len(models)
    bottom, height, area = np.zeros((n, c_max, 3)), np.zeros((n, c_max)), np.zeros((n, c_max))
    for i, (b, h, a) in enumerate(per_vessel):
        bottom[i, : len(h)], height[i, : len(h)], area[i, : len(h)] = b, h, a
    return Columns(bottom, height, area)


def buoyancy_wrench(
    cols: Columns,
    rot: Array,
    pos: Array,
    *,
    density: float,
    gravity: float,
    time_s: float = 0.0,
    surface: WaterHeight = water_height,
    eta: Array | None = None,
) -> Array:
    """Body-frame buoyancy wrench (N, 6) of all vessels given rotations (N,3,3), positions (N,3).
    `eta`: the water's height at the columns when the caller has it (`column_heights`).

    Each column's submerged fraction f is measured along its own axis (body z) from whichever
    end is lower, so a tilted or capsized hull is handled. Its force rho*g*A*h*f points up
    (world +z) and acts at the centroid of the submerged part: the total is rho*g times the
    submerged volume (Archimedes, exact for boxes) and tilt gives a restoring moment.
    """
    if eta is None:
        eta = column_heights(cols, rot, pos, time_s=time_s, surface=surface)
    tables = (cols.bottom_m, cols.height_m, cols.volume_m3)
    return kernels.buoyancy(_plain(rot), _plain(pos), tables, eta, density * gravity)


def column_heights(
    cols: Columns, rot: Array, pos: Array, *, time_s: float, surface: WaterHeight
) -> Array:
    """The water's height (N, C) above each column's bottom point (calm: zeros)."""
    columns = column_surface(surface)
    if surface is water_height:  # calm water: nothing to sample
        return cols.calm
    if columns is not None:  # a surface that evaluates columns itself
        return columns.at_columns(_plain(rot), cols.bottom_m)
    bottom_w = np.matmul(rot, cols.bottom_m, out=cols._world)  # (N, 3, C), world frame
    bottom_w += pos[:, :, None]
    eta = np.empty_like(cols.height_m)
    eta[...] = surface(bottom_w[:, 0], bottom_w[:, 1], time_s)
    return eta


def _plain(a: Array) -> Array:
    """C-contiguous float64, the one array type the kernels are compiled for."""
    return np.ascontiguousarray(a, dtype=np.float64)


def _plain_rows(rows: NDArray[np.intp]) -> NDArray[np.intp]:
    return np.ascontiguousarray(rows, dtype=np.intp)


# --- damping ----------------------------------------------------------------------------


def damping_wrench(
    nu_body: Array,
    linear: Array,
    quadratic: Array,
    water_velocity_body: Array | None = None,
    lift: Array | None = None,
) -> Array:
    """Fossen damping (N, 6): -(linear + quadratic*|nu_r|)*nu_r, per DOF, body frame, and
    the hulls' lift in a sideslip, `lift` (N, 2) [Y_uv, N_uv]: Y += Y_uv |u| v, N += N_uv u v
    (catabot/config/vessel.py, Damping).

    nu_body is [u, v, w, p, q, r] (N, 6); water_velocity_body (N, 3) is the current seen in the
    body frame, so damping acts on the velocity relative to the water.
    """
    nu_r = nu_body.copy()
    if water_velocity_body is not None:
        nu_r[:, :3] -= water_velocity_body
    wrench = -(linear + quadratic * np.abs(nu_r)) * nu_r
    if lift is not None:
        u, v = nu_r[:, 0], nu_r[:, 1]
        wrench[:, 1] += lift[:, 0] * np.abs(u) * v
        wrench[:, 5] += lift[:, 1] * u * v
    return wrench


# --- thrusters --------------------------------------------------------------------------


class ThrusterBank:
    """Thrusters of all vessels, padded to (N, T), with first-order lag on each force."""

    def __init__(self, layouts: Sequence[Sequence[Thruster]], dt_s: float) -> None:
        n, t_max = len(layouts), max((len(t) for t in layouts), default=0)
        self.count = [len(t) for t in layouts]
        self.position_m = np.zeros((n, t_max, 3))
        self.direction = np.zeros((n, t_max, 3))
        self.max_forward_n = np.zeros((n, t_max))
        self.max_reverse_n = np.zeros((n, t_max))
        self.alpha = np.ones((n, t_max))  # exact ZOH factor 1 - exp(-dt/tau)
        for i, layout in enumerate(layouts):
            for k, th in enumerate(layout):
                self.position_m[i, k] = th.position_m
                self.direction[i, k] = (np.cos(th.yaw_rad), np.sin(th.yaw_rad), 0.0)
                self.max_forward_n[i, k] = th.max_forward_n
                self.max_reverse_n[i, k] = th.max_reverse_n
                if th.time_constant_s > 0:
                    self.alpha[i, k] = -np.expm1(-dt_s / th.time_constant_s)
        self.command = np.zeros((n, t_max))
        self._count = np.array(self.count, dtype=np.intp)
        self.force_n = np.zeros((n, t_max))
        # Wrench per newton of each thruster, so that a step needs one contraction, no cross.
        moment_arm = np.cross(self.position_m, self.direction)
        self.unit_wrench = np.concatenate([self.direction, moment_arm], axis=2)  # (N, T, 6)

    def set_command(self, index: int, command: Array) -> None:
        """Store a validated, clamped command vector for vessel `index`."""
        self.command[index, : self.count[index]] = command

    def set_commands(self, rows: NDArray[np.intp], commands: Array) -> None:
        """Commands (len(rows), >= 1) for vessels `rows` at once, clamped to [-1, 1];
        columns past a vessel's thrusters are zeroed. ValueError, and nothing stored, when a
        value a vessel uses is not finite."""
        rows, commands = _plain_rows(rows), _plain(commands)
        bad = kernels.store_commands(self.command, self._count, rows, commands)
        if bad >= 0:
            raise ValueError(f"thrust commands: a value for row {int(rows[bad])} is not finite")

    def advance(self) -> None:
        """Move each delivered force one time step towards its commanded force."""
        c = self.command
        target = np.where(c >= 0.0, c * self.max_forward_n, c * self.max_reverse_n)
        self.force_n += self.alpha * (target - self.force_n)
