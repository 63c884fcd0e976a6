"""All bodies (vessels and buoys) as DART free-floating trees, GROUP trees per skeleton.

Why groups: DART's World does per-skeleton work every step, and dartpy reads or writes the
generalized vectors one skeleton per call. One skeleton per body costs, for 100 bodies,
~0.25 ms of calls and stepping per step; one skeleton for all bodies ~0.05 ms. But DART
solves all contacts of one skeleton as one constrained group and propagates every contact
impulse through every body of it: with 30 touching pairs (120 contacts) among 100 bodies a
single skeleton steps in ~7 ms against ~0.6 ms for one skeleton per body. Groups of 8-10
trees keep most of the speed (~0.07 ms) with a bounded contact cost (~0.7-1.4 ms for the
same pile-up), measured with dartpy 6.20. Bodies of one skeleton only collide with each
other when self-collision checking is on, so it is.

Vessels fill skeletons GROUP at a time, then buoys start skeletons of their own (so one of
buoys can rest as a whole, sleep.py): `slices[g]` are the rows of skeleton g. A body's
FreeJoint's 6 generalized coordinates follow the same conventions as a FreeJoint skeleton
of its own, and the concatenation of the skeletons' vectors is the (N, 6) layout
PhysicsWorld uses.

`TreeView` gives per-body access with the Skeleton methods other code uses on a vessel's own
skeleton (positions, velocities, forces, mass matrix, Coriolis and gravity forces, body node).
"""

from __future__ import annotations

from collections.abc import Sequence

import dartpy as dart
import numpy as np
from numpy.typing import NDArray

from catabot.config.vessel import VesselModel, load_vessel_model
from services.physics.hydro import Array

StartPose = tuple[float, float, float, float]  # x, y, z (m, map ENU), yaw (rad)


GROUP = 8  # trees per skeleton, see the module docstring


class Fleet:
    """The skeletons holding every body, and whole-fleet reads and writes of their vectors."""

    def __init__(
        self, bodies: Sequence[tuple[str, VesselModel, StartPose]], *, first_buoy: int | None = None
    ) -> None:
        """Rows from `first_buoy` on (buoys) start a skeleton of their own, so a skeleton of
        buoys can rest as a whole (sleep.py)."""
        n, split = len(bodies), len(bodies) if first_buoy is None else first_buoy
        self.starts = [*range(0, split, GROUP), *range(split, n, GROUP)]
        self.slices = [slice(a, b) for a, b in zip(self.starts, [*self.starts[1:], n], strict=True)]
        self.group_of = np.repeat(
            np.arange(len(self.starts)), [r.stop - r.start for r in self.slices]
        )
        self.skeletons: list[dart.dynamics.Skeleton] = []
        self.views: list[TreeView] = []
        for g, rows in enumerate(self.slices):
            members = bodies[rows]
            skel = dart.dynamics.Skeleton(f"fleet{g}")
            for vessel_id, model, _ in members:
                _add_body(skel, vessel_id, model)
            skel.setSelfCollisionCheck(True)
            skel.setAdjacentBodyCheck(False)
            q = np.zeros(6 * len(members))
            for k, (_, _, (x, y, z, yaw)) in enumerate(members):
                q[6 * k : 6 * k + 6] = (0.0, 0.0, yaw, x, y, z)
            skel.setPositions(q)
            self.skeletons.append(skel)
            self.views.extend(TreeView(skel, k) for k in range(len(members)))
        self._frozen: dict[int, tuple[Array, Array]] = {}  # group: its held q and v (sleep.py)
        self._world: dart.simulation.World | None = None  # set by add_to

    def add_to(self, world: dart.simulation.World) -> None:
        self._world = world  # a sleeping group leaves it (freeze)
        for skel in self.skeletons:
            world.addSkeleton(skel)

    def positions(self) -> Array:
        """Generalized positions of every body, (N, 6)."""
        held, skels = self._frozen, enumerate(self.skeletons)
        parts = [held[g][0] if g in held else s.getPositions() for g, s in skels]
        return np.concatenate(parts).reshape(-1, 6)

    def velocities(self) -> Array:
        """Generalized velocities of every body, (N, 6)."""
        held, skels = self._frozen, enumerate(self.skeletons)
        parts = [held[g][1] if g in held else s.getVelocities() for g, s in skels]
        return np.concatenate(parts).reshape(-1, 6)

    def freeze(self, group: int, *, frozen: bool) -> None:
        """Skeleton `group` out of the DART world and at rest (a sleeping group of buoys,
        sleep.py), or back in it; a frozen one is neither read nor written each step. Out of
        the world, not merely immobile and not collidable: DART still kept those in its
        collision detector's broadphase, which cost the waypoint row of Table II (265
        sleeping buoys) ≈40 µs a step, as much as the bodies' own dynamics."""
        skel, world = self.skeletons[group], self._world
        if frozen == (group in self._frozen):
            return
        assert world is not None, "Fleet.freeze before add_to"
        if frozen:
            skel.setVelocities(np.zeros(skel.getNumDofs()))
            self._frozen[group] = (skel.getPositions(), skel.getVelocities())
            world.removeSkeleton(skel)
        else:
            self._frozen.pop(group)
            world.addSkeleton(skel)

    def place(self, rows: NDArray[np.intp], q: Array, v: Array) -> None:
        """Bodies `rows` to generalized positions `q` and velocities `v` (k, 6 each)."""
        pos, vel = self.positions(), self.velocities()
        pos[rows], vel[rows] = q, v
        for part, skel in zip(self.slices, self.skeletons, strict=True):
            skel.setPositions(pos[part].ravel())
            skel.setVelocities(vel[part].ravel())

    def set_forces(self, generalized: Array) -> None:
        """Generalized forces of every body from an (N, 6) array."""
        for g, (rows, skel) in enumerate(zip(self.slices, self.skeletons, strict=True)):
            if g not in self._frozen:
                skel.setForces(generalized[rows].ravel())


def buoy_bodies(
    buoys: Sequence[tuple[str, tuple[float, float]]], model: VesselModel | None
) -> list[tuple[str, VesselModel, StartPose]]:
    """Buoys as bodies (bundled "buoy" model unless given), upright at their anchor points."""
    if not buoys:
        return []
    buoy = model if model is not None else load_vessel_model("buoy")
    return [(bid, buoy, (float(x), float(y), 0.0, 0.0)) for bid, (x, y) in buoys]


def _add_body(fleet: dart.dynamics.Skeleton, vessel_id: str, model: VesselModel) -> None:
    """A new tree: mass and inertia at the COG, a box collision shape over the hulls."""
    joint, body = fleet.createFreeJointAndBodyNodePair(None)
    joint.setName(vessel_id)
    body.setName(vessel_id)
    body.setMass(model.mass_kg)
    ixx, iyy, izz = model.inertia_kgm2
    body.setMomentOfInertia(ixx, iyy, izz, 0.0, 0.0, 0.0)
    body.setLocalCOM(np.asarray(model.cog_m, dtype=np.float64))
    lo, hi = model.hull_box()
    node = body.createShapeNode(dart.dynamics.BoxShape(hi - lo))
    node.setRelativeTranslation((lo + hi) / 2)
    node.createCollisionAspect()
    node.createDynamicsAspect()


class TreeView:
    """Body i of the fleet, seen as if it were a skeleton of its own (6 generalized DOFs)."""

    def __init__(self, fleet: dart.dynamics.Skeleton, index: int) -> None:
        self.fleet, self.index = fleet, index
        self._dofs = slice(6 * index, 6 * index + 6)

    def getName(self) -> str:
        return str(self.fleet.getBodyNode(self.index).getName())

    def getBodyNode(self, index: int = 0) -> dart.dynamics.BodyNode:
        if index != 0:
            raise IndexError("a fleet tree has exactly one body node (index 0)")
        return self.fleet.getBodyNode(self.index)

    def getPositions(self) -> Array:
        return np.array(self.fleet.getPositions()[self._dofs])

    def setPositions(self, q: Array) -> None:
        self.fleet.setPositions(self._spliced(self.fleet.getPositions(), q))

    def getVelocities(self) -> Array:
        return np.array(self.fleet.getVelocities()[self._dofs])

    def setVelocities(self, v: Array) -> None:
        self.fleet.setVelocities(self._spliced(self.fleet.getVelocities(), v))

    def setForces(self, tau: Array) -> None:
        self.fleet.setForces(self._spliced(self.fleet.getForces(), tau))

    def getMassMatrix(self) -> Array:
        return np.asarray(self.fleet.getMassMatrix(self.index))

    def getCoriolisAndGravityForces(self) -> Array:
        return np.asarray(self.fleet.getCoriolisAndGravityForces(self.index))

    def _spliced(self, full: Array, part: Array) -> Array:
        out = np.array(full, dtype=np.float64)
        out[self._dofs] = np.asarray(part, dtype=np.float64).ravel()
        return out
