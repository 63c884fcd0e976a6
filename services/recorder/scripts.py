"""The scenario's scripted commands, recorded as the commands they are (issue #17).

Physics applies a vessel's script step at the first tick at or after its `t_s`
(services/physics/commands.py); the recorder writes that step, at that tick, on the stream
an external command of its kind uses (`vessel/<id>/cmd/thrust` or `.../cmd/twist`), so the
CSV and `/<ns>/thrust` or `/<ns>/cmd_vel` in run.mcap hold every command a vessel was given,
scripted or sent. Stamp: the tick's, as for an external command (the tick physics applies
it at). Steps that fall on one tick: the last, the one physics follows. A vessel that a
command from the bus has taken over no longer follows its script (physics' precedence:
an outside thrust or twist until a `WaypointsCmd` hands it back, a lockstep controller's
set-point from then on), so its later steps are not written as if it had obeyed them; nor
are a traffic boat's set-points while an outside command holds it (`taken`).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from catabot.bus.messages import Message, ThrustCmd, TwistCmd
from catabot.config.scenario import ScriptStep
from catabot.world.orders import Orders
from catabot.world.world import World


class ScriptedCommands:
    """Every vessel's script steps by the tick they take effect at."""

    def __init__(self, world: World, orders: Orders) -> None:
        dt = world.scenario.dt_ns
        self._due: dict[int, dict[str, ScriptStep]] = {}
        for vessel in world.vessels:
            for step, t_ns in zip(vessel.script, vessel.script_ns, strict=True):
                tick = -(-t_ns // dt)  # the first tick at or after the step's time
                self._due.setdefault(tick, {})[vessel.id] = step
        self._keys = world.keys
        self._orders = orders

    def taken(self, ids: Sequence[str]) -> NDArray[np.bool_]:
        """Which of these traffic boats an outside command holds: physics does not follow
        their set-points, so a batch's rows for them are not written (they were, every
        guidance tick, while the boat obeyed the outside command)."""
        held = self._orders.held
        return np.fromiter((b in held for b in ids), dtype=bool, count=len(ids))

    def due(self, tick: int, stamp_ns: int) -> list[tuple[str, Message]]:
        """(stream, command) of every step that takes effect at `tick`, for the vessels that
        still follow their script."""
        out: list[tuple[str, Message]] = []
        for vessel, step in self._due.get(tick, {}).items():
            if not self._orders.follows_script(vessel):
                continue
            if step.thrust is not None:
                key = self._keys.cmd_thrust(vessel)
                out.append((key, ThrustCmd(tuple(step.thrust), tick=tick, stamp_ns=stamp_ns)))
            elif step.twist is not None:
                key = self._keys.cmd_twist(vessel)
                twist = step.twist
                cmd = TwistCmd(twist.surge_mps, twist.yaw_rate_radps, tick=tick, stamp_ns=stamp_ns)
                out.append((key, cmd))
        return [(self._keys.relative(key), cmd) for key, cmd in out]
