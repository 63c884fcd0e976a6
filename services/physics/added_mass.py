"""Added mass as a force on DART's rigid bodies, stable even when it exceeds the rigid mass.

The model (Fossen 2011, §6.3, current irrotational and uniform):
    M_RB nu_dot + C_RB(nu) nu + M_A nu_r_dot + C_A(nu_r) nu_r = tau,   nu_r = nu - nu_c,
with nu = [v, w] the body-frame twist at the body origin, nu_c = [R^T v_c, 0] the water's
velocity there, and nu_r_dot = nu_dot + [w x nu_c, 0] (the water's velocity held as it is
over a step, so its body components turn with the hull). In waves v_c is the current plus
the orbital velocity: the Munk terms then see the flow past the hull, and a body that rides
the orbit with the water feels none. With the current alone, a buoy in the medium swell
felt a roll moment -A22 v w from its own orbit and tilted up to 0.46 rad from the surface
normal in a sea no steeper than 0.11 rad (0.07 rad now). The water's acceleration (its
Froude-Krylov force and the added mass's share of it) is wave_pull.py's, an applied load.
M_A = diag(A11 .. A66) acts as inertia in all six DOF. DART integrates only M_RB and its own
rigid-body Coriolis and centripetal terms C_RB(nu) nu (about the COG) and gravity; C_A is ours.

C_A: Fossen's eq. 6.43 for a diagonal M_A (Kirchhoff form, momenta pa1 = A_lin * v_r,
pa2 = A_ang * w, C_A nu_r = [w x pa1, v_r x pa1 + w x pa2]) built from the MANOEUVRING added
masses A11, A22, A66 only (A33, A44, A55 set to zero inside C_A). This keeps the surge/sway
centripetal terms and the yaw Munk moment (A22 - A11) u v, and leaves out the vertical-plane
Munk terms such as (A33 - A11) u w in pitch: strip theory cancels those with the forward-speed
potential damping (Salvesen, Tuck & Faltinsen 1970: B53 = U A33) that a diagonal damping
model lacks, and alone they are badly wrong: with them the bundled monohull (A33 = 4.5 m)
porpoises out of the water at 5 m/s.

Why not a lagged acceleration: applying -M_A a[k-1] as a force makes a[k] = (F - M_A a[k-1]) /
m, an iteration with gain -A/m that diverges once A >= m and rings before: heave added mass
is often larger than the mass for flat hulls. Why not heavier bodies: DART's body has one
scalar mass, so anisotropic added mass cannot be put there, and gravity would grow with it.

What we do instead is exact for a rigid body: M_RB is a constant 6 x 6 matrix in the body
frame (mass, COG offset r_g, inertia about the origin), so before each step we solve the
augmented equation for the acceleration DART is about to produce,
    (M_RB + M_A) nu_dot = tau + tau_g - C_RB(nu) nu - C_A(nu_r) nu_r - M_A [w x nu_c, 0],
with tau_g the gravity wrench, and apply tau_A = -M_A nu_r_dot - C_A(nu_r) nu_r. Given tau_A,
DART's rigid update M_RB nu_dot = tau + tau_g - C_RB nu + tau_A has that very nu_dot as its
solution (same state, same semi-implicit Euler step), so the motion is the one of the body
with M_RB + M_A: unconditionally stable in the added mass, no lag. Limits: contact impulses
(collisions) act on the rigid mass only, and a spatially varying current's gradient is not in
nu_c's derivative.
"""

from __future__ import annotations

import copy
from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from catabot.config.vessel import VesselModel
from services.physics import kernels
from services.physics.hydro import Array
from services.physics.wet import scaled_added_mass


def rigid_body_matrix(model: VesselModel) -> Array:
    """M_RB (6, 6) about the body origin, Fossen order [linear, angular], body axes."""
    m = model.mass_kg
    r = np.asarray(model.cog_m, dtype=np.float64)
    s = np.array([[0.0, -r[2], r[1]], [r[2], 0.0, -r[0]], [-r[1], r[0], 0.0]])  # S(r) b = r x b
    inertia_o = np.diag(model.inertia_kgm2) + m * (r @ r * np.eye(3) - np.outer(r, r))
    return np.block([[m * np.eye(3), -m * s], [m * s, inertia_o]])


class AddedMass:
    """Added-mass wrench for the vessels whose model has any; the others get zero."""

    def __init__(self, models: Sequence[VesselModel], gravity: float) -> None:
        diag = np.array([m.added_mass for m in models], dtype=np.float64).reshape(-1, 6)
        self.count = len(models)
        self.rows = np.flatnonzero(diag.any(axis=1))
        self.all_rows = self.rows.size == self.count
        chosen = [models[int(i)] for i in self.rows]
        self.diag = diag[self.rows]
        self.coriolis_diag = self.diag * [1.0, 1.0, 0.0, 0.0, 0.0, 1.0]  # A11, A22, A66
        self.mass = np.array([m.mass_kg for m in chosen]).reshape(-1, 1)
        self.cog = np.array([m.cog_m for m in chosen], dtype=np.float64).reshape(-1, 3)
        self.m_rb = np.array([rigid_body_matrix(m) for m in chosen]).reshape(-1, 6, 6)
        augmented = self.m_rb + np.einsum("ni,ij->nij", self.diag, np.eye(6))
        self.inverse = np.linalg.inv(augmented) if len(chosen) else augmented
        self.gravity = float(gravity)

    def take(self, rows: NDArray[np.intp]) -> AddedMass:
        """The same for bodies `rows` (sorted) alone, in that order (forces.py)."""
        sub = copy.copy(self)
        keep = np.flatnonzero(np.isin(self.rows, rows))
        sub.count, sub.rows = len(rows), np.searchsorted(rows, self.rows[keep])
        sub.all_rows = sub.rows.size == sub.count
        for name in ("diag", "coriolis_diag", "mass", "cog", "m_rb", "inverse"):
            setattr(sub, name, getattr(self, name)[keep])
        return sub

    @property
    def active(self) -> bool:
        return self.rows.size > 0

    def wrench(
        self, rot: Array, nu: Array, current_b: Array, other: Array, *, wet: Array | None = None
    ) -> Array:
        """tau_A (N, 6), body frame, given every other applied wrench `other` (N, 6).

        rot (N, 3, 3) body to world; nu (N, 6) body twist; current_b (N, 3) the current in
        the body frame. `other` excludes gravity, which DART applies and which is added here.
        `wet` (N,): the share of each body's added mass that acts (None: all of it).
        """
        if self.all_rows:
            return self._solve(rot[:, 2, :], nu, current_b, other, wet)
        out = np.zeros((self.count, 6))
        if self.active:
            r = self.rows
            out[r] = self._solve(rot[r, 2, :], nu[r], current_b[r], other[r], wet)
        return out

    def _solve(self, z_b: Array, nu: Array, nu_c: Array, other: Array, wet: Array | None) -> Array:
        """tau_A for the chosen rows (kernels.added_mass); z_b is the world up axis in body
        coordinates."""
        tables = self._tables(None if wet is None else wet[self.rows])
        z_b, nu, nu_c, other = (np.ascontiguousarray(a) for a in (z_b, nu, nu_c, other))
        return kernels.added_mass(tables, z_b, nu, nu_c, other, self.gravity)

    def _tables(self, wet: Array | None) -> tuple[Array, Array, Array, Array, Array, Array]:
        """The kernel's tables, with M_A scaled by `wet` for the rows out of the water
        (their augmented inverse solved again, wet.scaled_added_mass)."""
        inverse, diag, coriolis = self.inverse, self.diag, self.coriolis_diag
        if wet is not None and wet.size and wet.min() < 1.0:
            inverse, diag, coriolis = scaled_added_mass(
                self.m_rb, inverse, diag, coriolis, np.ascontiguousarray(wet)
            )
        return (self.m_rb, inverse, diag, coriolis, self.mass, self.cog)
