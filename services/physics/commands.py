"""Which command each vessel follows at a tick: scripted, or the latest from the bus.

Scripted steps are applied at the first tick boundary at or after their time; a command
from the bus replaces the scripted one from the next tick on and stays until another
arrives (the vessel keeps the last order it was given, as a real autopilot does); a release
hands it back to the script step in force, or to rest before its first step.

Traffic boats: the traffic service's set-points arrive in one lockstep `TwistBatch` per
tick on `world/cmd/twist`. Precedence, outside > lockstep set-point > script, is
catabot/world/orders.py's; the set-points' values live here in arrays, whatever their count.
"""

from __future__ import annotations

import logging
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from catabot.bus.messages import Message, ThrustCmd, TwistBatch, TwistCmd, WaypointsCmd
from catabot.config.scenario import ScriptStep
from catabot.run.advice import advise, tell
from catabot.world.orders import Orders, command_timeouts, script_step
from catabot.world.world import Body

Array = NDArray[np.float64]

log = logging.getLogger("physics.commands")


@dataclass(frozen=True)
class Order:
    """A vessel's current order: direct thrust or a velocity set-point."""

    thrust: tuple[float, ...] | None = None
    twist: tuple[float, float] | None = None


class CommandBook:
    """Orders of every vessel. Set-points from the lockstep (the traffic batch, or a lockstep
    participant's twist) live in arrays, so `orders` costs a few array operations a tick
    whatever the number of boats; external overrides and scripts, few, stay per vessel."""

    def __init__(self, vessels: Sequence[Body]) -> None:
        self.ids = tuple(v.id for v in vessels)
        self.row = {vid: i for i, vid in enumerate(self.ids)}
        self.thrusters = {v.id: len(v.model.thrusters) for v in vessels}
        self.scripts = {v.id: v.script for v in vessels}  # in time order
        self.times = {v.id: v.script_ns for v in vessels}
        self.scripted = [v.id for v in vessels if v.script]
        self.released: set[str] = set()  # handed back this tick (`take`)
        self.book = Orders(command_timeouts(vessels))  # who holds each: outside, set-points
        self.boats = {v.id for v in vessels if v.kind == "boat"}  # back to their behaviour
        self.set_point = np.zeros((len(self.ids), 2))  # (surge m/s, yaw rate rad/s)
        self.has_set_point = np.zeros(len(self.ids), dtype=bool)
        self._batch_rows: dict[tuple[str, ...], NDArray[np.intp]] = {}  # a traffic shard's

    def order(self, vessel: str, stamp_ns: int) -> Order:
        """One vessel's order now: external > lockstep set-point > script."""
        held = self.book.held.get(vessel)
        if held is not None:
            return _from_command(held)
        i = self.row[vessel]
        if self.has_set_point[i]:
            surge, rate = self.set_point[i].tolist()
            return Order(twist=(surge, rate))
        step = script_step(self.scripts[vessel], self.times[vessel], self.thrusters[vessel],
                           stamp_ns)  # fmt: skip
        return _from_step(step)

    def orders(self, stamp_ns: int) -> tuple[dict[int, tuple[float, ...]], NDArray[np.intp], Array]:
        """Every vessel's order: thrust values by row, then the rows under velocity control
        and their (surge, yaw rate) targets, rows in `ids` order."""
        for vid in self.book.expire(stamp_ns):  # outside commands gone stale: handed back
            self.released.add(vid)
            held_s = self.book.timeouts[vid] / 1e9
            advise(log, f"{vid}: no outside command for {held_s:g} s ({self._field(vid)}): "
                        f"handed back at t = {stamp_ns / 1e9:g} s to {self._own(vid)}")  # fmt: skip
        target, follow = self.set_point.copy(), self.has_set_point.copy()
        thrust: dict[int, tuple[float, ...]] = {}
        for vid in self.scripted:
            if not follow[self.row[vid]]:
                _place(self.order(vid, stamp_ns), self.row[vid], target, follow, thrust)
        for vid in self.released.difference(self.scripted):  # no script: back to rest
            if not follow[self.row[vid]]:
                _place(self.order(vid, 0), self.row[vid], target, follow, thrust)
        self.released.clear()
        for vid, held in self.book.held.items():
            _place(_from_command(held), self.row[vid], target, follow, thrust)
        rows = np.flatnonzero(follow)
        return thrust, rows, target[rows]

    def drop(self, participant: str, vessels: Sequence[str], stamp_ns: int) -> None:
        """`participant` left the run, which goes on without it (clock.policy drop): the
        vessels it drove no longer hold its last command or set-point (a crashed stack's boat
        sailed on to the end, and only conductor.log said why), back to script or rest."""
        for vessel in vessels:
            self.book.drop(vessel)
            self.has_set_point[self.row[vessel]] = False
            self.released.add(vessel)
        if vessels:  # a lockstep controller drives scenario vessels only
            tell(log, f"{participant} left the run at t = {stamp_ns / 1e9:g} s (clock.policy "
                      f"drop): {some(vessels)} back to script (rest without one)")  # fmt: skip

    def _own(self, vessel: str) -> str:
        """What a vessel follows when nobody outside holds it."""
        return "the traffic's guidance" if vessel in self.boats else "its script (rest without one)"

    def _or_timeout(self, vessel: str) -> str:
        timeout_ns = self.book.timeouts.get(vessel)
        if timeout_ns is None:  # a boat had been told of a command_timeout_s it cannot have
            return ""
        return f" or {timeout_ns / 1e9:g} s without one ({self._field(vessel)})"

    def _field(self, vessel: str) -> str:
        """The scenario field of a vessel's command timeout."""
        return "traffic.command_timeout_s" if vessel in self.boats else "command_timeout_s"

    def take_batch(self, batch: TwistBatch, expected: tuple[str, ...]) -> None:
        """The traffic service's set-points (rows and shapes checked on arrival): every boat
        with finite values adopts its own, the others keep their previous order."""
        rows = self._rows_of(expected)
        ok = np.isfinite(batch.surge) & np.isfinite(batch.yaw_rate)
        self.set_point[rows[ok], 0] = batch.surge[ok]
        self.set_point[rows[ok], 1] = batch.yaw_rate[ok]
        self.has_set_point[rows[ok]] = True
        if not ok.all():
            bad = [expected[i] for i in np.flatnonzero(~ok)]
            log.error("refused twist set-points at tick %d: non-finite for %s", batch.tick, bad)

    def _rows_of(self, boats: tuple[str, ...]) -> NDArray[np.intp]:
        rows = self._batch_rows.get(boats)
        if rows is None:
            rows = self._batch_rows[boats] = np.array([self.row[b] for b in boats], np.intp)
        return rows

    def take(self, vessel: str, msgs: list[Message], stamp_ns: int = 0) -> None:
        """Adopt the newest command from the bus (checked on arrival: one finite value per
        thruster, a finite twist: catabot/bus/checks.py). A lockstep twist (tick >= 0) is a
        set-point; an outside command (tick -1) takes the vessel over."""
        for msg in msgs:
            was = self.book.held.get(vessel)
            if self.book.heard(vessel, msg, stamp_ns=stamp_ns) and isinstance(msg, WaypointsCmd):
                self.released.add(vessel)
            now = self.book.held.get(vessel)
            if _outside(now) and not _outside(was):  # another stack drives it: say when
                kind = "thrust" if isinstance(msg, ThrustCmd) else "twist"
                until = f"a release (waypoints){self._or_timeout(vessel)}"
                tell(log, f"{vessel}: taken over by an outside {kind} at t = {stamp_ns / 1e9:g} "
                          f"s; it holds the vessel until {until}")  # fmt: skip
            elif _outside(was) and now is None:  # a release: said as a take-over is
                tell(
                    log,
                    f"{vessel}: handed back (waypoints) at t = {stamp_ns / 1e9:g} s, to "
                    f"{self._own(vessel)}",
                )
            if isinstance(msg, TwistCmd) and msg.tick >= 0:
                self.set_point[self.row[vessel]] = (msg.surge, msg.yaw_rate)
                self.has_set_point[self.row[vessel]] = True


def _place(
    order: Order, row: int, target: Array, follow: NDArray[np.bool_], thrust: dict[int, Any]
) -> None:
    """Write one vessel's order into the arrays `orders` returns."""
    follow[row] = order.twist is not None
    if order.twist is not None:
        target[row] = order.twist
    elif order.thrust is not None:
        thrust[row] = order.thrust


def _from_command(cmd: ThrustCmd | TwistCmd) -> Order:
    if isinstance(cmd, ThrustCmd):
        return Order(thrust=cmd.thrust)
    return Order(twist=(cmd.surge, cmd.yaw_rate))


def _from_step(step: ScriptStep) -> Order:
    if step.thrust is not None:
        return Order(thrust=tuple(step.thrust))
    assert step.twist is not None
    return Order(twist=(step.twist.surge_mps, step.twist.yaw_rate_radps))


def some(ids: Sequence[str], shown: int = 5) -> str:
    """A list of ids short enough for one console line."""
    more = f" and {len(ids) - shown} more" if len(ids) > shown else ""
    return ", ".join(ids[:shown]) + more


def _outside(held: Message | None) -> bool:
    """An outside command (tick -1), not the vessel's own lockstep thrust controller's."""
    return held is not None and getattr(held, "tick", 0) < 0
