"""Grounding: hull-bottom contact with the terrain, as linearly implicit penalty forces.

Why not DART's own mesh contact. dartpy 6.20's default detector is FCL, and it does collide a
box with a MeshShape (checked: a box rests on an 800-triangle slope). But dartpy cannot build a
MeshShape from arrays (it wants an assimp aiScene, which only its URDF/SDF file loaders make),
the full image is 13 M triangles (tiles would have to be written out, loaded and swapped as the
vessels move), and every other force on a vessel is already vectorised NumPy. So the ground is
queried where it is exact and cheap, the height field itself: a probe point below
`terrain.height()` is in contact. A height field is a half-space below its surface, so a fast
vessel cannot tunnel through it, and nothing depends on a mesh resolution.

The law, per probe (a grid over each hull's underside, body frame): an isotropic spring-damper
to a contact point, F = -k e - c v, where e is the penetration along the terrain normal
(distance below the local tangent plane) plus the tangential stretch from an anchor set where
the probe touched down. The normal part never pulls, and the tangential part is capped at mu N
(the anchor slides while the cap holds): stick-slip friction, so a vessel pushed against a shore
stays put instead of creeping as a viscous "Coulomb" law would let it.

Why implicit. Explicit penalty forces must be soft to be stable at dt = 0.01 s, and the
stiffness budget has to be split over all the probes that could touch at once, so the two or
three probes of a bow against a steep bank are very soft: measured, 5-30 cm of steady
penetration and a monohull that never came to rest (sharing the budget among the probes in
contact instead makes the law jump as probes touch down, and it rang in a limit cycle). So each
vessel's contact is integrated with one linearised backward-Euler step, as DART will integrate
it: with M DART's mass matrix, K and C the probes' stiffness and damping mapped to the body's
six velocities (sums of J^T J), and bias DART's Coriolis and gravity terms,
    (M + dt C + dt^2 K) dv = dt (f_ext - bias + f0 - dt K v0),
and the force applied is each probe's end-of-step force f0 - dt K v1 - C dv, then clamped (no
pull, friction cap). The linear part is unconditionally stable, so the contact can be stiff: the
weight on four probes sinks 5 mm (less on more), a bow held against a bank by full thrust a
few mm. Added mass (loads.py) is accounted for in `_added_mass`. A capsized hull is not handled
(probes are on the bottom only); buoyancy knows nothing about the terrain.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import dartpy as dart
import numpy as np
from numpy.typing import NDArray

from catabot.config.vessel import VesselModel
from catabot.world import rotations
from catabot.world.hulls import PROBE_SPACING_M, model_probes
from catabot.world.terrain import Terrain
from services.physics.hydro import Array

Index = NDArray[np.intp]


@dataclass(frozen=True)
class ContactParams:
    """Contact law settings (see the module docstring for why these values)."""

    friction: float = 0.5  # Coulomb coefficient, hull on wet sand or mud (an estimate)
    sag_m: float = 0.005  # sink under the whole weight resting on `support_probes` probes
    support_probes: int = 4  # e.g. a hull on a rock under its four corners
    damping_ratio: float = 1.0  # of that heave mode: a grounding hull does not bounce
    probe_spacing_m: float = PROBE_SPACING_M  # along and across each hull bottom


class Grounding:
    """Terrain contact forces for every vessel, probes padded to (N, P) like hydro.Columns.

    Friction anchors are state: call `generalized_forces` exactly once per step.
    """

    def __init__(
        self,
        terrain: Terrain,
        models: Sequence[VesselModel],
        dt_s: float,
        skeletons: Sequence[dart.dynamics.Skeleton],
        params: ContactParams | None = None,
    ) -> None:
        self.terrain, self.params, self._dt = terrain, params or ContactParams(), float(dt_s)
        self._skeletons = list(skeletons)
        per_vessel = [model_probes(m, self.params.probe_spacing_m) for m in models]
        n, width = len(models), max(len(q) for q in per_vessel)
        self.probes_m, self.valid = np.zeros((n, width, 3)), np.zeros((n, width), dtype=bool)
        for i, q in enumerate(per_vessel):
            self.probes_m[i, : len(q)], self.valid[i, : len(q)] = q, True
        weight = np.array([m.mass_kg for m in models])[:, None]
        support = np.minimum(self.valid.sum(axis=1, keepdims=True), self.params.support_probes)
        self._k = weight * 9.81 / (self.params.sag_m * support) * self.valid  # (N, P), N/m
        self._c = 2 * self.params.damping_ratio * np.sqrt(self._k * weight / support)  # N s/m
        self._added = np.array([m.added_mass for m in models], dtype=np.float64).reshape(n, 6)
        self._has_added_mass = bool(self._added.any())
        self._radius = np.sqrt((self.probes_m**2).sum(-1).max(axis=1))
        self._anchor = np.zeros((n, width, 3))
        self._touching = np.zeros((n, width), dtype=bool)
        self._block_m, self._block_max = _block_maxima(terrain, float(self._radius.max()))
        self.penetration_m = np.zeros(n)  # deepest probe below the terrain, last step (vertical)
        self.force_n = np.zeros((n, 3))  # total contact force, world frame, last step

    def near_ground(self, pos: Array) -> Index:
        """Indices of vessels whose probes could reach the terrain (a block-maximum test)."""
        nby, nbx = self._block_max.shape
        cell = np.nan_to_num(pos[:, :2] / self._block_m).astype(np.intp)
        bx, by = np.clip(cell[:, 0], 0, nbx - 1), np.clip(cell[:, 1], 0, nby - 1)
        return np.flatnonzero(self._block_max[by, bx] > pos[:, 2] - self._radius)

    def generalized_forces(
        self, rot: Array, pos: Array, vel_w: Array, external: Array, *, wet: Array | None = None
    ) -> Array:
        """(N, 6) DART FreeJoint forces [moment about the body origin, force], world frame.

        rot (N, 3, 3), pos (N, 3) and vel_w [w, v] (N, 6) are the state at the step's start;
        external (N, 6) are the other generalized forces of this step (buoyancy, thrust, ...);
        wet (N,) the share of each body's added mass that acted (forces.wetness; None: all).
        """
        out = np.zeros((len(pos), 6))
        self.penetration_m[:] = 0.0
        self.force_n[:] = 0.0
        active = self.near_ground(pos)
        idle = np.ones(len(pos), dtype=bool)
        idle[active] = False
        self._touching[idle] = False
        if active.size:
            share = None if wet is None else wet[active]
            contact, out[active] = self._contact(
                active, rot[active], pos[active], vel_w[active], external, share
            )
            self.force_n[active] = contact[:, 3:]
        return out

    def _contact(
        self, idx: Index, rot: Array, pos: Array, vel: Array, ext: Array, wet: Array | None
    ) -> tuple[Array, Array]:
        """Generalized contact forces of the vessels `idx` (one implicit step, then clamps):
        the physical one and the one to apply to DART (they differ with added mass)."""
        r = np.einsum("aij,apj->api", rot, self.probes_m[idx])
        pt = pos[:, None, :] + r
        normal, below = self._ground(pt)
        engaged = (below > 0.0) & self.valid[idx]
        self.penetration_m[idx] = np.where(engaged, below, 0.0).max(axis=1)
        k, c = self._k[idx] * engaged, self._c[idx] * engaged
        anchor = np.where((engaged & self._touching[idx])[..., None], self._anchor[idx], pt)
        stretch = pt - anchor
        stretch -= (stretch * normal).sum(-1, keepdims=True) * normal
        error = stretch - (below * normal[..., 2])[..., None] * normal  # e: into the ground < 0
        f0 = -k[..., None] * error - c[..., None] * _point_velocity(vel, r)
        mass, bias = self._dynamics(idx)
        m_eff = mass + self._added_mass(idx, rot, wet)
        free = _mul(m_eff, _solve(mass, ext[idx] - bias))  # M_eff times the contact-free accel.
        stiff, damp = _jtj(k, r), _jtj(c, r)
        lhs = m_eff + self._dt * damp + self._dt**2 * stiff
        dv = _solve(lhs, self._dt * (free + _jt(f0, r) - self._dt * _mul(stiff, vel)))
        force = (
            f0
            - self._dt * k[..., None] * _point_velocity(vel + dv, r)
            - c[..., None] * _point_velocity(dv, r)
        )
        force = self._clamp(idx, force, normal, pt, anchor, k, engaged)
        contact = _jt(force, r)
        if not self._has_added_mass:
            return contact, contact
        return contact, _mul(mass, _solve(m_eff, contact))  # see _added_mass

    def _ground(self, pt: Array) -> tuple[Array, Array]:
        """Unit terrain normals (A, P, 3) and vertical depth below the surface (A, P)."""
        gx, gy = self.terrain.slope(pt[..., 0], pt[..., 1])
        nz = 1.0 / np.sqrt(1.0 + gx * gx + gy * gy)
        normal = np.stack([-gx * nz, -gy * nz, nz], axis=-1)
        return normal, self.terrain.height(pt[..., 0], pt[..., 1]) - pt[..., 2]

    def _dynamics(self, idx: Index) -> tuple[Array, Array]:
        """DART's mass matrices (A, 6, 6) and Coriolis + gravity terms (A, 6) of `idx`."""
        skels = [self._skeletons[i] for i in idx]
        mass = np.array([s.getMassMatrix() for s in skels], dtype=np.float64)
        bias = np.array([s.getCoriolisAndGravityForces() for s in skels], dtype=np.float64)
        return mass, bias

    def _added_mass(self, idx: Index, rot: Array, wet: Array | None) -> Array:
        """Added mass (A, 6, 6) in DART's coordinates: blockdiag(R A_ang R^T, R A_lin R^T),
        the share `wet` of it that acted (a hull aground on dry land has none).

        The added-mass force (loads.py) is computed from the other loads before contact is
        known, as if the hull would accelerate freely. Contact is therefore solved with the
        effective mass M + M_A, and the contact force f is applied as M (M + M_A)^-1 f: the
        same acceleration the added-mass force would give had it seen f. Without this a
        grounded hull with a large heave added mass is held up by a phantom added-mass force.
        """
        r, added = rot, self._added[idx] if wet is None else self._added[idx] * wet[:, None]
        lin, ang = added[:, :3], added[:, 3:]
        out = np.zeros((len(idx), 6, 6))
        out[:, :3, :3] = np.einsum("aij,aj,akj->aik", r, ang, r)
        out[:, 3:, 3:] = np.einsum("aij,aj,akj->aik", r, lin, r)
        return out

    def _clamp(
        self,
        idx: Index,
        force: Array,
        normal: Array,
        pt: Array,
        anchor: Array,
        k: Array,
        engaged: NDArray[np.bool_],
    ) -> Array:
        """No pull; friction at most mu N, the anchor sliding so its spring holds the cap."""
        push = (force * normal).sum(-1)
        pressing = engaged & (push > 0.0)
        push = np.where(pressing, push, 0.0)
        tangent = force - push[..., None] * normal
        size = np.linalg.norm(tangent, axis=-1)
        limit = self.params.friction * push
        slip = size > limit
        tangent *= np.where(slip, limit / np.maximum(size, 1e-12), 1.0)[..., None]
        slide = pt + tangent / np.maximum(k, 1e-12)[..., None]  # anchor whose spring = cap
        self._anchor[idx] = np.where(slip[..., None], slide, anchor)
        self._touching[idx] = pressing
        return np.where(pressing[..., None], push[..., None] * normal + tangent, 0.0)


def _solve(a: Array, b: Array) -> Array:
    """Batched solve of (A, 6, 6) systems for (A, 6) right-hand sides."""
    return np.asarray(np.linalg.solve(a, b[..., None])[..., 0], dtype=np.float64)


def _mul(a: Array, b: Array) -> Array:
    """Batched (A, 6, 6) @ (A, 6)."""
    return np.einsum("aij,aj->ai", a, b)


def _point_velocity(vel: Array, r: Array) -> Array:
    """Velocity (A, P, 3) of points at offsets r from the origins moving with [w, v] (A, 6)."""
    return vel[:, None, 3:] + rotations.cross(vel[:, None, :3], r)


def _jt(force: Array, r: Array) -> Array:
    """Generalized force [sum r x F, sum F] (A, 6) of point forces (A, P, 3) at offsets r."""
    return np.concatenate([rotations.cross(r, force).sum(axis=1), force.sum(axis=1)], axis=1)


def _jtj(w: Array, r: Array) -> Array:
    """sum_i w_i J_i^T J_i (A, 6, 6) for isotropic point springs, J_i = [-[r_i]x, I]."""
    a = len(w)
    eye = np.eye(3)
    s0, s1 = w.sum(axis=1), np.einsum("ap,api->ai", w, r)
    s2 = np.einsum("ap,api,apj->aij", w, r, r)
    out = np.zeros((a, 6, 6))
    out[:, :3, :3] = np.trace(s2, axis1=1, axis2=2)[:, None, None] * eye - s2
    out[:, :3, 3:] = _skew(s1)
    out[:, 3:, :3] = -_skew(s1)
    out[:, 3:, 3:] = s0[:, None, None] * eye
    return out


def _skew(v: Array) -> Array:
    """Cross-product matrices (A, 3, 3): _skew(a) @ b = a x b."""
    out = np.zeros((len(v), 3, 3))
    out[:, 0, 1], out[:, 0, 2], out[:, 1, 2] = -v[:, 2], v[:, 1], -v[:, 0]
    out[:, 1, 0], out[:, 2, 0], out[:, 2, 1] = v[:, 2], -v[:, 1], v[:, 0]
    return out


def _block_maxima(terrain: Terrain, reach_m: float) -> tuple[float, Array]:
    """(block size m, (nby, nbx) maximum elevation over each block and its 8 neighbours).

    A block is at least the vessels' reach plus one pixel, so every height a vessel's probes
    can sample (bilinear: up to one pixel beyond the point) lies within its block's neighbours.
    """
    mpp, z = terrain.metres_per_pixel, terrain.elevation_m
    b = max(4, math.ceil(reach_m / mpp) + 2)
    ny, nx = z.shape
    padded = np.pad(z, ((0, -ny % b), (0, -nx % b)), mode="edge")
    blocks = padded.reshape(padded.shape[0] // b, b, padded.shape[1] // b, b).max(axis=(1, 3))
    ring = np.pad(blocks, 1, mode="edge")
    nby, nbx = blocks.shape
    shifts = [ring[dy : dy + nby, dx : dx + nbx] for dy in range(3) for dx in range(3)]
    return b * mpp, np.max(shifts, axis=0)
