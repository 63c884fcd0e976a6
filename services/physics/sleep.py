"""Resting buoys that DART skips until something comes near them.

Why: Table II's waypoint row has 275 buoys beside 101 boats, and DART stepped all 376 bodies
(≈1.5 ms a step, 0.15 ms without the buoys) although a moored buoy on calm water sits still.
Under steady loads (no waves, no gusts: the current map, a steady wind and the moorings do
not change in time) a body at rest stays at rest, so freezing it changes its state by no
more than the motion it has when it is frozen (below REST_SPEED); physics engines call this
sleeping (Bullet, PhysX).

The unit is a fleet skeleton (fleet.py: GROUP trees), because DART skips a whole skeleton:
one of buoys only falls asleep when every member has been still for REST_STEPS steps, the
sea is steady and no moving body is near; it leaves the DART world (fleet.py), its
velocities zeroed, and the force model leaves its rows out (forces.py). It wakes at the
start of a step (before that step's forces) in which a moving body comes within
WAKE_MARGIN_M (plus what that body covers in WAKE_LOOKAHEAD_S) of a member's bounding
circle, so contacts only ever happen between awake bodies, and all wake when a run-time
setting changes the environment. Vessels never sleep: they have thrusters and orders.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from catabot.config.vessel import VesselModel
from services.physics.fleet import Fleet
from services.physics.hydro import Array

REST_SPEED = 1e-3  # m/s and rad/s: slower than this counts as still
REST_STEPS = 100  # still this long (1 s at 100 Hz) before a group sleeps
WAKE_MARGIN_M = 1.0
WAKE_LOOKAHEAD_S = 1.0
CHECK_S = 0.1  # how often the (bodies x sleepers) distances are tested: well inside the lookahead


class Sleep:
    """Which buoy-only skeletons are asleep, and the rules that change it."""

    def __init__(self, fleet: Fleet, radii: Array, first_buoy: int, *, dt_s: float) -> None:
        self.fleet, self.radii = fleet, np.asarray(radii, dtype=np.float64)
        self.group_of = fleet.group_of
        count = len(fleet.skeletons)
        self.groups = np.array([g for g in range(count) if fleet.starts[g] >= first_buoy], int)
        self.still = np.zeros(len(self.radii), dtype=np.int64)  # consecutive still steps
        self.asleep = np.zeros(count, dtype=bool)
        self.every, self.steps = max(1, round(CHECK_S / dt_s)), 0
        self.version = 0  # counts changes of the sleeping set (forces.AwakeTables)

    def rows_asleep(self) -> NDArray[np.bool_]:
        return self.asleep[self.group_of]

    def wake_near(self, pos: Array, vel_w: Array) -> None:
        """Before a step: wake every sleeping group a moving body may reach (tested every
        CHECK_S: in between no body covers more than a fraction of its lookahead)."""
        self.steps += 1
        if self.steps % self.every or not self.asleep.any():
            return
        sleeping = self.rows_asleep()
        near = _near(pos, vel_w, self.radii, np.flatnonzero(sleeping), np.flatnonzero(~sleeping))
        for g in np.unique(self.group_of[near]):
            self._set(int(g), asleep=False)

    def settle(self, pos: Array, vel_w: Array, *, steady: bool) -> None:
        """After a step: count still steps and put the groups that qualify to sleep."""
        if not steady or self.groups.size == 0:
            self.still[:] = 0
            return
        speed = np.max(np.abs(vel_w), axis=1)
        self.still = np.where(speed < REST_SPEED, self.still + 1, 0)
        ready = self._ready_groups() if self.steps % self.every == 0 else self.groups[:0]
        if ready.size == 0:
            return
        sleeping = self.rows_asleep() | np.isin(self.group_of, ready)
        near = _near(pos, vel_w, self.radii, np.flatnonzero(sleeping), np.flatnonzero(~sleeping))
        for g in np.setdiff1d(ready, self.group_of[near]):
            self._set(int(g), asleep=True)

    def wake_all(self) -> None:
        for g in np.flatnonzero(self.asleep):
            self._set(int(g), asleep=False)
        self.still[:] = 0
        self.version += 1  # the environment changed: tables taken before are stale

    def _ready_groups(self) -> NDArray[np.intp]:
        """Awake buoy groups whose every member has been still long enough."""
        least = np.minimum.reduceat(self.still, self.fleet.starts)  # per skeleton
        g = self.groups
        return g[~self.asleep[g] & (least[g] >= REST_STEPS)]

    def _set(self, group: int, *, asleep: bool) -> None:
        self.fleet.freeze(group, frozen=asleep)
        self.asleep[group] = asleep
        self.version += 1
        self.still[self.group_of == group] = 0


def _near(
    pos: Array, vel_w: Array, radii: Array, sleeping: NDArray[np.intp], moving: NDArray[np.intp]
) -> NDArray[np.intp]:
    """The sleeping rows some moving body may reach: plan-view circles with a margin."""
    if sleeping.size == 0 or moving.size == 0:
        return sleeping[:0]
    reach = radii[moving] + WAKE_MARGIN_M + WAKE_LOOKAHEAD_S * np.hypot(*vel_w[moving, 3:5].T)
    dx = np.subtract.outer(pos[sleeping, 0], pos[moving, 0])
    dy = np.subtract.outer(pos[sleeping, 1], pos[moving, 1])
    limit = np.add.outer(radii[sleeping], reach)
    close = dx * dx + dy * dy < limit * limit
    return sleeping[close.any(axis=1)]


def plan_radii(models: list[VesselModel]) -> Array:
    """Each body's plan-view circle around its hulls, about its origin."""
    return np.array([_plan_radius(m) for m in models])


def _plan_radius(model: VesselModel) -> float:
    lo, hi = model.hull_box()
    return float(np.hypot(max(-lo[0], hi[0]), max(-lo[1], hi[1])))
