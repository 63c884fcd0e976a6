"""`metrics.json`: navigation figures, accumulated tick by tick from the recorded states.

Computed by the recorder from the `BodyStates` every stack produces, so a stack is measured
the same way whatever it is. Every vessel (scenario vessels and traffic boats): distance
travelled and top speed over the ground (horizontal: a boat heaving in a swell, or dropped
by a change of sea, goes nowhere), final position. Each scenario vessel (what a stack
drives), against everything else: the nearest vessel, buoy and shore it came to (centre to
centre; shore: the nearest land pixel), its goal and route (`tasks.py`), its thrust impulse,
and episodes (`episodes.py`): encounters (another vessel within
`recording.encounter_radius_m`, with the closest point of approach), collisions (plan-view
hull boxes within `CONTACT_M`, the physics collision shapes; other vessels and buoys),
groundings (`seabed.py`) and capsizes (its deck's normal below the horizon, with its largest
tilt: a boat on its side or upside down floats on, and its states alone do not say so). The
traffic's own collisions, boat with boat or buoy, are `fleet_contacts.py`'s.

Cost: arrays of (scenario vessels x bodies) per tick, no loop over bodies (DESIGN.md §8).
Written with `repr` floats and sorted keys so two runs of one seed give the same bytes.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from catabot.bus.clock import NS_PER_S
from catabot.bus.messages import BodyStates
from catabot.config.rates import traffic_record_period
from catabot.world import rotations
from catabot.world.hulls import CONTACT_M, boxes_touch, footprints
from catabot.world.orders import Orders
from catabot.world.world import World
from services.recorder.episodes import Episodes
from services.recorder.fleet_contacts import FleetContacts
from services.recorder.metrics_json import write_metrics
from services.recorder.seabed import Seabed
from services.recorder.tasks import Goals, Routes, Thrust, rowdot

EPISODE_GAP_S = 1.0  # a contact that stops for less than this is the same contact


class Metrics:
    def __init__(self, world: World, orders: Orders) -> None:
        self.ids = [v.id for v in world.vessels]  # the first rows of every batch
        self.scenario, self.seed = world.scenario.name, world.scenario.seed  # metrics.json's
        self.body_ids = list(world.body_ids)
        subjects = world.bodies[: len(world.scenario.vessels)]
        self.subjects = len(subjects)
        n, s = len(self.ids), self.subjects
        self.distance = np.zeros(n)
        self.max_speed2 = np.zeros(n)  # squared: one sqrt at the end
        self.last: np.ndarray | None = None
        self.stamp_ns = 0
        self.skipped = 0  # state batches with a non-finite position, left out
        self.dropped: dict[str, float] = {}  # participant: from when (s), clock.policy drop
        self.offset, self.half = footprints([b.model for b in world.bodies])
        self.reach = np.hypot(*self.offset.T) + np.hypot(*self.half.T)  # the box within it
        self.nearest = {kind: _Nearest(s) for kind in ("vessel", "buoy", "shore")}
        gap = round(EPISODE_GAP_S * NS_PER_S)
        total = len(self.body_ids)
        self.encounters = Episodes((s, n), gap_ns=0)
        self.collisions = Episodes((s, total), gap_ns=gap)
        self.groundings = Episodes((s,), gap_ns=gap)
        self.capsizes = Episodes((s,), gap_ns=gap)
        self.max_tilt = np.zeros(s)  # rad: the body's z axis from the world's vertical
        period = traffic_record_period(world.scenario)
        self.fleet = FleetContacts(
            self.offset, self.half, self.reach, first=s, period=period, gap_ns=gap
        )
        self.radius = world.scenario.recording.encounter_radius_m
        self.pair_ok = np.ones((s, total), dtype=bool)  # each pair once, never a body itself
        self.pair_ok[:, :s] = np.triu(np.ones((s, s), dtype=bool), k=1)
        self.least_gap = np.full((s, total), np.inf)  # to every body, over the run
        self.pair_vessels = self.pair_ok[:, :n]
        self.itself = (np.arange(s), np.arange(s))
        self.no_pairs = np.zeros((s, total), dtype=bool)
        self.reach_sum = self.reach[:s, None] + self.reach[None, :] + CONTACT_M
        tasks = [v.task for v in world.scenario.vessels]
        self.goals, self.routes = Goals(tasks), Routes(tasks)
        self.thrust = Thrust(subjects, world.scenario.dt_ns, orders)
        self.seabed = Seabed(world.terrain, subjects) if world.terrain is not None else None

    def order_changed(self, vessel: str) -> None:
        """The thrust in force from now on (`tasks.Thrust`)."""
        self.thrust.changed(vessel)

    def add(self, batch: BodyStates) -> None:
        n, s, stamp = len(self.ids), self.subjects, batch.stamp_ns
        everything = np.asarray(batch.position)
        if not np.isfinite(everything).all():  # a diverged body: no figure can use it
            self.skipped += 1
            return
        self.fleet.add(batch)
        pos = everything[:n]
        if self.last is not None:  # over the ground: a boat heaving in waves travels no way
            step = pos[:, :2] - self.last[:, :2]
            self.distance += np.sqrt(rowdot(step, step))
        self.last = pos.copy()
        vel = np.asarray(batch.linear_velocity[:n])  # body frame: less its map-up part
        up = rotations.vertical(np.asarray(batch.orientation[:n]), vel)
        np.maximum(self.max_speed2, rowdot(vel, vel) - up * up, out=self.max_speed2)
        self.stamp_ns = stamp
        gap = np.hypot(
            everything[None, :, 0] - pos[:s, None, 0], everything[None, :, 1] - pos[:s, None, 1]
        )
        gap[self.itself] = np.inf
        np.minimum(self.least_gap, gap, out=self.least_gap)
        vessels = gap[:, :n]
        self.nearest["vessel"].add(vessels, stamp)
        self.nearest["buoy"].add(gap[:, n:], stamp)
        self.encounters.update(self.pair_vessels & (vessels <= self.radius), stamp, vessels)
        self._collisions(batch, gap, stamp)
        quat = np.asarray(batch.orientation[:s])
        self._tilt(quat, stamp)
        if self.seabed is not None:
            shore, shallow = self.seabed.check(pos[:s])
            if shore is not None:
                self.nearest["shore"].add(shore[:, None], stamp)
            self.groundings.update(self.seabed.aground(pos[:s], quat, shallow), stamp)
        self.goals.add(pos, self.distance, stamp)
        self.routes.add(pos)
        self.thrust.add(stamp)

    def _tilt(self, quat: np.ndarray, stamp: int) -> None:
        """Heel and trim together: the angle of the body's z axis from the vertical, whose
        world z is 1 - 2 (x^2 + y^2) of the (x, y, z, w) quaternion; past 90 deg, capsized."""
        up = 1.0 - 2.0 * (quat[:, 0] ** 2 + quat[:, 1] ** 2)
        np.maximum(self.max_tilt, np.arccos(np.clip(up, -1.0, 1.0)), out=self.max_tilt)
        self.capsizes.update(up < 0.0, stamp)

    def _collisions(self, batch: BodyStates, gap: np.ndarray, stamp: int) -> None:
        """Hull boxes of the pairs whose bounding circles are within reach, tested exactly."""
        near = self.pair_ok & (gap <= self.reach_sum)
        touching = self.no_pairs
        if near.any():
            touching = np.zeros_like(near)
            a, b = np.nonzero(near)
            position = np.asarray(batch.position)[:, :2]
            boxes = (self.offset, self.half)
            touching[a, b] = boxes_touch(position, np.asarray(batch.orientation), boxes, a, b)
        self.collisions.update(touching, stamp)

    def write(self, path: Path, *, end_reason: str = "") -> None:
        write_metrics(self, path, end_reason=end_reason)


class _Nearest:
    """Per scenario vessel: the least distance to anything of one kind, what and when."""

    def __init__(self, s: int) -> None:
        self.distance = np.full(s, np.inf)
        self.what = np.full(s, -1, dtype=np.intp)
        self.at_ns = np.zeros(s, dtype=np.int64)

    def add(self, gap: np.ndarray, stamp_ns: int) -> None:
        if gap.shape[1] == 0:
            return
        least = np.minimum.reduce(gap, axis=1)
        better = least < self.distance
        if better.any():  # which body, only when the record improves
            self.distance[better] = least[better]
            self.what[better] = np.argmin(gap[better], axis=1)
            self.at_ns[better] = stamp_ns
