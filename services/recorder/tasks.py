"""Metrics against each vessel's task (vessels[].task): the goal, the route, and the thrust.

Goal: the time of the first recorded state inside the goal disc and the path length
travelled until then. Route: the cross-track error, the distance from the vessel's origin
to the nearest point of the route polyline, every tick (max and RMS over the run).
Thrust impulse: sum over thrusters of |F| dt (N s), F the force the thrust command in force
asks for (c * max_forward_n, or |c| * max_reverse_n for c < 0; the thrusters' lag is not
modelled). The commands are those the recorder sees: scripted thrust steps and `cmd/thrust`
from the bus. Under velocity control (a twist set-point, scripted or sent) the thrust is
the controller's, not on the bus: that time is counted as `thrust_unknown_s` instead.
"""

from __future__ import annotations

import bisect
from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from catabot.bus.clock import NS_PER_S
from catabot.bus.messages import ThrustCmd
from catabot.config.task import TaskConfig
from catabot.world.orders import Orders
from catabot.world.world import Body

Array = NDArray[np.float64]


class Goals:
    """Goal discs of the vessels that have one; rows index the scenario vessels."""

    def __init__(self, tasks: Sequence[TaskConfig | None]) -> None:
        goals = [(i, t.goal) for i, t in enumerate(tasks) if t is not None and t.goal is not None]
        self.rows = np.array([i for i, _ in goals], dtype=np.intp)
        picked = [g for _, g in goals]
        self.centre = np.array([(g.x_m, g.y_m) for g in picked]).reshape(-1, 2)
        self.radius = np.array([g.radius_m for g in picked])
        self.reached_ns = np.full(len(self.rows), -1, dtype=np.int64)
        self.path_m = np.zeros(len(self.rows))
        self.radius2 = self.radius * self.radius
        self.all_reached = not len(self.rows)
        self.pending = np.ones(len(self.rows), dtype=bool)

    def add(self, pos: Array, travelled: Array, stamp_ns: int) -> None:
        if self.all_reached:
            return
        off = pos[self.rows, :2] - self.centre
        new = (rowdot(off, off) <= self.radius2) & self.pending
        if new.any():
            self.pending &= ~new
            self.reached_ns[new] = stamp_ns
            self.path_m[new] = travelled[self.rows[new]]
            self.all_reached = bool((self.reached_ns >= 0).all())

    def final_distance(self, pos: Array) -> Array:
        """Metres from each goal's centre at the end (pos: the last positions)."""
        return np.hypot(*(pos[self.rows, :2] - self.centre).T)


class Routes:
    """Cross-track error of the vessels with a route: every segment of every route in one
    array, the nearest per vessel by `minimum.reduceat`."""

    def __init__(self, tasks: Sequence[TaskConfig | None]) -> None:
        routes = [
            (i, np.asarray(t.route, dtype=np.float64))
            for i, t in enumerate(tasks)
            if t is not None and t.route is not None
        ]
        self.rows = np.array([i for i, _ in routes], dtype=np.intp)
        seg = [len(r) - 1 for _, r in routes]
        self.owner = np.repeat(np.arange(len(routes)), seg)
        self.first = np.concatenate([[0], np.cumsum(seg)[:-1]]).astype(np.intp)
        self.a = np.concatenate([r[:-1] for _, r in routes]) if routes else np.zeros((0, 2))
        b = np.concatenate([r[1:] for _, r in routes]) if routes else np.zeros((0, 2))
        self.ab = b - self.a
        self.len2 = np.maximum((self.ab * self.ab).sum(axis=1), 1e-300)  # a point: t = 0
        self.seg_rows = self.rows[self.owner]
        self.max2 = np.zeros(len(routes))  # squared: one sqrt at the end
        self.sum2 = np.zeros(len(routes))
        self.ticks = 0

    def add(self, pos: Array) -> None:
        if not len(self.rows):
            return
        rel = pos[self.seg_rows, :2] - self.a
        t = rowdot(rel, self.ab) / self.len2
        np.minimum(np.maximum(t, 0.0, out=t), 1.0, out=t)
        rel -= t[:, None] * self.ab
        xte2 = np.minimum.reduceat(rowdot(rel, rel), self.first)
        np.maximum(self.max2, xte2, out=self.max2)
        self.sum2 += xte2
        self.ticks += 1

    def max(self) -> Array:
        return np.sqrt(self.max2)

    def rms(self) -> Array:
        return np.sqrt(self.sum2 / max(self.ticks, 1))


class Thrust:
    """The commanded thrust force of each scenario vessel (N, summed over its thrusters), and
    its integral. Commands change rarely: the force is re-derived only when the order in
    force changes (`orders`, physics' rule) or a script step begins, and the integral is
    added up then, so a tick costs a counter. A command from the bus counts from the tick
    physics took it (`BodyStates.commands`, told before that tick's batch is added)."""

    def __init__(self, bodies: Sequence[Body], dt_ns: int, orders: Orders) -> None:
        self.dt_s = dt_ns / NS_PER_S
        self.dt_ns = dt_ns
        self.bodies = list(bodies)
        self.orders = orders
        self.row = {b.id: i for i, b in enumerate(bodies)}
        self.times = [b.script_ns for b in bodies]
        self.events = sorted({t for ts in self.times for t in ts})
        self.next_event = 0
        self.force = np.zeros(len(bodies))
        self.known = np.ones(len(bodies), dtype=bool)
        self.impulse = np.zeros(len(bodies))
        self.unknown_ticks = np.zeros(len(bodies), dtype=np.int64)  # counted, not summed in s
        self.pending = 0  # ticks driven by the current forces, not yet added up
        self.began = -1  # the stamp the last tick began at (a released vessel's script step)
        for i in range(len(bodies)):
            self._resolve(i, -1)

    def changed(self, vessel: str) -> None:
        """The order in force for `vessel` changed (a command from the bus, or a release)."""
        i = self.row.get(vessel)
        if i is not None:
            self._settle()
            self._resolve(i, self.began)

    def add(self, stamp_ns: int) -> None:
        """The state at `stamp_ns` ends the tick that began at stamp_ns - dt: the orders in
        force then drove it."""
        began = self.began = stamp_ns - self.dt_ns
        while self.next_event < len(self.events) and self.events[self.next_event] <= began:
            self.next_event += 1
            self._settle()
            for i in range(len(self.bodies)):
                self._resolve(i, began)
        self.pending += 1  # added up when a force changes: nothing per tick

    def totals(self) -> tuple[Array, Array]:
        """(thrust impulse N s, seconds under velocity control) per vessel, so far. The
        seconds from a count of ticks: summed in seconds, 30 s came out 29.990000000000155."""
        self._settle()
        return self.impulse, self.unknown_ticks * self.dt_ns / NS_PER_S

    def _settle(self) -> None:
        if self.pending:
            span = self.pending * self.dt_s
            self.impulse += self.force * span
            self.unknown_ticks += ~self.known * self.pending
            self.pending = 0

    def _resolve(self, i: int, began: int) -> None:
        msg = self.orders.in_force(self.bodies[i].id)
        if isinstance(msg, ThrustCmd):
            self.force[i], self.known[i] = self._newtons(i, msg.thrust), True
            return
        if msg is not None:  # a twist: the velocity controller's thrust is not on the bus
            self.force[i], self.known[i] = 0.0, False
            return
        k = bisect.bisect_right(self.times[i], began) - 1
        step = self.bodies[i].script[k] if k >= 0 else None
        if step is not None and step.thrust is None:  # a scripted twist
            self.force[i], self.known[i] = 0.0, False
        else:
            self.force[i] = self._newtons(i, step.thrust if step and step.thrust else [])
            self.known[i] = True

    def _newtons(self, i: int, command: Sequence[float]) -> float:
        thrusters = self.bodies[i].model.thrusters
        c = np.clip(np.asarray(command, dtype=np.float64)[: len(thrusters)], -1.0, 1.0)
        fwd = np.array([t.max_forward_n for t in thrusters])[: len(c)]
        rev = np.array([t.max_reverse_n for t in thrusters])[: len(c)]
        return float(np.where(c >= 0, c * fwd, -c * rev).sum())


def rowdot(a: Array, b: Array) -> Array:
    """Row-wise dot products: a ufunc reduce, cheaper than einsum's dispatch on small arrays
    (the metrics' per-tick cost is dominated by calls on a few rows)."""
    out: Array = np.add.reduce(a * b, axis=1)
    return out
