"""All bodies (vessels and buoys) as ONE DART skeleton with one free-floating tree per body.

Why one skeleton: DART's World does per-skeleton work every step (dynamics, integration,
collision bookkeeping), and dartpy can only read or write generalized vectors skeleton by
skeleton. With 101 separate skeletons that overhead and 303 Python calls per step cost
about 0.6 ms; a single multi-tree skeleton reads all positions and velocities in one call
each and takes all forces in one call, and DART steps it several times faster.

Tree i holds body i: a FreeJoint whose 6 generalized coordinates are entries 6i .. 6i+5 of
the skeleton's vectors (same conventions as a FreeJoint skeleton of its own). Bodies of one
skeleton only collide with each other when self-collision checking is on, so it is.

`TreeView` gives per-body access with the Skeleton methods other code uses on a vessel's own
skeleton (positions, velocities, forces, mass matrix, Coriolis and gravity forces, body node).
"""

from __future__ import annotations

from collections.abc import Sequence

import dartpy as dart
import numpy as np

from catabot.vessel import VesselModel
from services.physics.hydro import Array

StartPose = tuple[float, float, float, float]  # x, y, z (m, map ENU), yaw (rad)


def make_fleet(bodies: Sequence[tuple[str, VesselModel, StartPose]]) -> dart.dynamics.Skeleton:
    """One skeleton, one free rigid body per entry, in order, each at its start pose."""
    fleet = dart.dynamics.Skeleton("fleet")
    for vessel_id, model, _ in bodies:
        _add_body(fleet, vessel_id, model)
    fleet.setSelfCollisionCheck(True)
    fleet.setAdjacentBodyCheck(False)
    q = np.zeros(6 * len(bodies))
    for i, (_, _, (x, y, z, yaw)) in enumerate(bodies):
        q[6 * i : 6 * i + 6] = (0.0, 0.0, yaw, x, y, z)
    fleet.setPositions(q)
    return fleet


def _add_body(fleet: dart.dynamics.Skeleton, vessel_id: str, model: VesselModel) -> None:
    """A new tree: mass and inertia at the COG, a box collision shape over the hulls."""
    joint, body = fleet.createFreeJointAndBodyNodePair(None)
    joint.setName(vessel_id)
    body.setName(vessel_id)
    body.setMass(model.mass_kg)
    ixx, iyy, izz = model.inertia_kgm2
    body.setMomentOfInertia(ixx, iyy, izz, 0.0, 0.0, 0.0)
    body.setLocalCOM(np.asarray(model.cog_m, dtype=np.float64))
    lo, hi = hull_bounds(model)
    node = body.createShapeNode(dart.dynamics.BoxShape(hi - lo))
    node.setRelativeTranslation((lo + hi) / 2)
    node.createCollisionAspect()
    node.createDynamicsAspect()


def hull_bounds(model: VesselModel) -> tuple[Array, Array]:
    """Axis-aligned body-frame box around all hulls."""
    lows, highs = [], []
    for hull in model.hulls:
        half = np.array([hull.length_m, hull.beam_m, hull.vertical_extent_m]) / 2
        centre = np.asarray(hull.center_m, dtype=np.float64)
        lows.append(centre - half)
        highs.append(centre + half)
    return np.min(lows, axis=0), np.max(highs, axis=0)


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
