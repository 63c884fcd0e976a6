"""How far each hull is in the water, and which propellers are: a hull out of the water
feels no water.

Why: the force laws took every hull for a floating one. A catamaran dropped from 10 m fell
at 1.2 m/s, its weight over its heave damping, with its heave added mass in the air; with
full thrust 20 m up it flew forward and pitched 71 degrees; capsized, its propellers in the
air drove it at 1.2 m/s. Now damping and added mass act as far as the hull is in the water
(`wetness`) and a thruster pushes only below the surface (`ThrustLoad`). Both compiled
(numba, as kernels.py): as NumPy passes they cost 0.14 ms a step for 101 vessels.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from services.physics.hydro import Array, WaterHeight, column_surface, water_height
from services.physics.kernels import jit


def wetness(buoyancy: Array, rot: Array, weight_n: Array) -> Array | None:
    """Each hull's share of the water's damping and added mass, in [0, 1]: all of it while
    it displaces at least half its floating volume (buoyancy >= weight / 2), then in
    proportion down to none in the air; None when every hull is that wet (the usual step).
    Why half: about its equilibrium, bobbing in a swell or in a free decay, a hull keeps its
    model's full damping and added mass, as the model's figures assume."""
    out = np.empty(len(weight_n))
    return out if _wetness(rot, buoyancy, weight_n, out) else None


@jit
def _wetness(rot: Array, buoyancy: Array, weight: Array, out: Array) -> bool:
    """`out` filled, True when some hull is less than fully wet. No gravity (weight 0): no
    buoyancy tells, so the model's full figures."""
    dry = False
    for i in range(len(out)):
        if weight[i] <= 0.0:
            out[i] = 1.0
            continue
        up = rot[i, 2, 0] * buoyancy[i, 0] + rot[i, 2, 1] * buoyancy[i, 1]
        share = 2.0 * (up + rot[i, 2, 2] * buoyancy[i, 2]) / weight[i]
        out[i] = min(max(share, 0.0), 1.0)
        dry = dry or out[i] < 1.0
    return dry


@jit
def scaled_added_mass(
    m_rb: Array, inverse: Array, diag: Array, coriolis: Array, wet: Array
) -> tuple[Array, Array, Array]:
    """added_mass.AddedMass's inverse, diagonal and manoeuvring part with each row's M_A
    times `wet`, the augmented (M_RB + wet M_A)^-1 solved again for the rows not fully wet
    (Gauss-Jordan on the 6 x 6, symmetric positive definite; in a swell some hull is
    partly out of the water most steps, and NumPy's batched inverse cost 0.14 ms a step)."""
    if len(wet) != len(diag):
        raise ValueError("scaled_added_mass: one wetness per row of the tables")
    inv, d, c = inverse.copy(), diag.copy(), coriolis.copy()
    a = np.empty((6, 12))
    for i in range(len(wet)):
        if wet[i] >= 1.0:
            continue
        for k in range(6):
            d[i, k] *= wet[i]
            c[i, k] *= wet[i]
        for r in range(6):
            for k in range(6):
                a[r, k] = m_rb[i, r, k] + (d[i, r] if r == k else 0.0)
                a[r, 6 + k] = 1.0 if r == k else 0.0
        for k in range(6):
            pivot = a[k, k]
            for j in range(12):
                a[k, j] /= pivot
            for r in range(6):
                if r != k:
                    factor = a[r, k]
                    for j in range(12):
                        a[r, j] -= factor * a[k, j]
        inv[i] = a[:, 6:]
    return inv, d, c


@dataclass(frozen=True)
class ThrustLoad:
    """Delivered thruster forces (N, T), their wrenches per newton (N, T, 6) and positions
    (N, T, 3), body frame."""

    force_n: Array
    unit_wrench: Array
    position_m: Array

    def take(self, rows: NDArray[np.intp]) -> ThrustLoad:
        return ThrustLoad(self.force_n[rows], self.unit_wrench[rows], self.position_m[rows])

    def wrench(self, rot: Array, pos: Array, surface: WaterHeight, time_s: float) -> Array:
        """Body-frame wrench (N, 6) about the body origin of the thrusters under water; in
        waves the surface above each: a vessel's own expansion, compiled, as for its columns
        (its NumPy form cost 0.1 ms a step for 101 vessels), else `surface` at world points."""
        x, y, z = _thruster_points(rot, pos, self.position_m)
        columns = column_surface(surface)
        if columns is not None:
            z = z - columns.at_columns(rot, self.position_m.transpose(0, 2, 1).copy())
        elif surface is not water_height:
            z = z - surface(x, y, time_s)
        return _immersed_wrench(self.force_n, self.unit_wrench, z)


@jit
def _thruster_points(rot: Array, pos: Array, at: Array) -> tuple[Array, Array, Array]:
    """World x, y, z (N, T) of thrusters at body points `at` (N, T, 3)."""
    n, t = at.shape[0], at.shape[1]
    x, y, z = np.empty((n, t)), np.empty((n, t)), np.empty((n, t))
    for i in range(n):
        for k in range(t):
            p = at[i, k]
            x[i, k] = pos[i, 0] + rot[i, 0, 0] * p[0] + rot[i, 0, 1] * p[1] + rot[i, 0, 2] * p[2]
            y[i, k] = pos[i, 1] + rot[i, 1, 0] * p[0] + rot[i, 1, 1] * p[1] + rot[i, 1, 2] * p[2]
            z[i, k] = pos[i, 2] + rot[i, 2, 0] * p[0] + rot[i, 2, 1] * p[1] + rot[i, 2, 2] * p[2]
    return x, y, z


@jit
def _immersed_wrench(force: Array, unit: Array, depth: Array) -> Array:
    """Sum of force x unit wrench over each body's thrusters below the surface (depth < 0)."""
    out = np.zeros((force.shape[0], 6))
    for i in range(force.shape[0]):
        for k in range(force.shape[1]):
            if depth[i, k] < 0.0 and force[i, k] != 0.0:
                for j in range(6):
                    out[i, j] += force[i, k] * unit[i, k, j]
    return out


def warm_up() -> None:
    """Load these kernels now (kernels.warm_up says why)."""
    rot, one = np.eye(3)[None], np.ones((1, 1))
    wetness(np.zeros((1, 6)), rot, np.ones(1))
    six = np.eye(6)[None]
    scaled_added_mass(six, six, np.ones((1, 6)), np.ones((1, 6)), np.full(1, 0.5))
    ThrustLoad(one, np.zeros((1, 1, 6)), np.zeros((1, 1, 3))).wrench(
        rot, np.zeros((1, 3)), water_height, 0.0
    )
