"""Which command each vessel follows at a tick: scripted, or the latest from the bus.

Scripted steps are applied at the first tick boundary at or after their time; a command
from the bus replaces the scripted one from the next tick on and stays until another
arrives (the vessel keeps the last order it was given, as a real autopilot does).

Traffic boats: the traffic service's set-points arrive in one lockstep `TwistBatch` per
tick on `world/cmd/twist`. An external command (tick -1, twist or thrust) outranks them
and holds the boat until a `WaypointsCmd` arrives for it (release, or a new path that
the traffic service then steers): external > traffic set-point > script.
"""

from __future__ import annotations

import bisect
import logging
from dataclasses import dataclass

import numpy as np

from catabot import codec
from catabot.clock import NS_PER_S
from catabot.messages import Message, ThrustCmd, TwistBatch, TwistCmd, WaypointsCmd
from catabot.scenario import ScriptStep, VesselConfig

log = logging.getLogger("physics.commands")


@dataclass(frozen=True)
class Order:
    """A vessel's current order: direct thrust or a velocity set-point."""

    thrust: tuple[float, ...] | None = None
    twist: tuple[float, float] | None = None


class CommandBook:
    def __init__(self, vessels: list[VesselConfig], thrusters: dict[str, int]) -> None:
        self.thrusters = thrusters
        self.scripts = {v.id: sorted(v.script, key=lambda s: s.t_s) for v in vessels}
        self.times = {
            vid: [round(s.t_s * NS_PER_S) for s in steps] for vid, steps in self.scripts.items()
        }
        self.external: dict[str, Order] = {}
        self.lockstep: dict[str, Order] = {}

    def order(self, vessel: str, stamp_ns: int) -> Order:
        if vessel in self.external:
            return self.external[vessel]
        if vessel in self.lockstep:
            return self.lockstep[vessel]
        index = bisect.bisect_right(self.times[vessel], stamp_ns) - 1
        return _from_step(self.scripts[vessel][index]) if index >= 0 else Order()

    def take_batch(self, batch: TwistBatch, expected: tuple[str, ...]) -> None:
        """The traffic service's set-points: every boat with finite values adopts its own."""
        try:
            batch.check(expected)
        except ValueError as exc:
            log.error("refused %s", exc)
            return
        surge, rate = batch.surge.tolist(), batch.yaw_rate.tolist()
        ok = np.isfinite(batch.surge) & np.isfinite(batch.yaw_rate)
        for i in np.flatnonzero(ok).tolist():
            self.lockstep[expected[i]] = Order(twist=(surge[i], rate[i]))
        if not ok.all():
            bad = [expected[i] for i in np.flatnonzero(~ok)]
            log.error("refused twist set-points at tick %d: non-finite for %s", batch.tick, bad)

    def take(self, vessel: str, key: str, msgs: list[Message]) -> None:
        """Adopt the newest valid command from the bus; refuse non-finite ones loudly."""
        for msg in msgs:
            if isinstance(msg, WaypointsCmd):
                self.external.pop(vessel, None)  # handed back (to traffic or the script)
            elif isinstance(msg, TwistCmd) and msg.tick >= 0 and codec.finite(msg.surge):
                if codec.finite(msg.yaw_rate):
                    self.lockstep[vessel] = Order(twist=(msg.surge, msg.yaw_rate))
            elif isinstance(msg, ThrustCmd) and len(msg.thrust) != self.thrusters[vessel]:
                log.error(
                    "refused command on %s: %d values for %d thrusters",
                    key,
                    len(msg.thrust),
                    self.thrusters[vessel],
                )
            elif isinstance(msg, ThrustCmd) and codec.finite(msg.thrust):
                self.external[vessel] = Order(thrust=msg.thrust)
            elif isinstance(msg, TwistCmd) and codec.finite((msg.surge, msg.yaw_rate)):
                self.external[vessel] = Order(twist=(msg.surge, msg.yaw_rate))
            else:
                log.error("refused command on %s: non-finite value in %s", key, msg)


def _from_step(step: ScriptStep) -> Order:
    if step.thrust is not None:
        return Order(thrust=tuple(step.thrust))
    assert step.twist is not None
    return Order(twist=(step.twist.surge_mps, step.twist.yaw_rate_radps))
