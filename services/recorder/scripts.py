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
are a traffic boat's set-points while an outside command holds it (`taken`). A release
hands a scenario vessel back: the step in force (or rest before the first) is written at
the tick physics resumes it (`resumed`).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from catabot.bus.messages import Message, ThrustCmd, TwistCmd
from catabot.config.live import tick_at
from catabot.config.scenario import ScriptStep
from catabot.world.orders import Orders, script_step
from catabot.world.world import World


class ScriptedCommands:
    """Every vessel's script steps by the tick they take effect at."""

    def __init__(self, world: World, orders: Orders) -> None:
        dt = world.scenario.dt_ns
        self._due: dict[int, dict[str, ScriptStep]] = {}
        self._dt_ns = dt
        self._scenario_vessels = {v.id: v for v in world.vessels if v.kind == "vessel"}
        for vessel in world.vessels:
            for step in vessel.script:
                self._due.setdefault(tick_at(step.t_s, dt), {})[vessel.id] = step
        self._keys = world.keys
        self._orders = orders

    def taken(self, ids: Sequence[str]) -> NDArray[np.bool_]:
        """Which of these traffic boats an outside command holds: physics does not follow
        their set-points, so a batch's rows for them are not written (they were, every
        guidance tick, while the boat obeyed the outside command)."""
        held = self._orders.held
        return np.fromiter((b in held for b in ids), dtype=bool, count=len(ids))

    def resumed(self, vessel: str, tick: int, stamp_ns: int) -> tuple[str, Message] | None:
        """The order a scenario vessel released at `tick` follows again (physics' rule): the
        script step in force, or rest before its first step; None when a step begins at
        `tick` itself (`due` writes it)."""
        body = self._scenario_vessels.get(vessel)
        if body is None or vessel in self._due.get(tick, {}):
            return None
        thrusters = len(body.model.thrusters)
        step = script_step(body.script, body.script_ns, thrusters, tick * self._dt_ns)
        return self._command(vessel, step, tick, stamp_ns)

    def due(self, tick: int, stamp_ns: int) -> list[tuple[str, Message]]:
        """(stream, command) of every step that takes effect at `tick`, for the vessels that
        still follow their script."""
        return [
            self._command(vessel, step, tick, stamp_ns)
            for vessel, step in self._due.get(tick, {}).items()
            if self._orders.follows_script(vessel)
        ]

    def _command(
        self, vessel: str, step: ScriptStep, tick: int, stamp_ns: int
    ) -> tuple[str, Message]:
        """(stream, command) of one step, as the command of its kind would be sent."""
        if step.thrust is not None:
            cmd: Message = ThrustCmd(tuple(step.thrust), tick=tick, stamp_ns=stamp_ns)
            return self._keys.relative(self._keys.cmd_thrust(vessel)), cmd
        assert step.twist is not None
        twist = step.twist
        cmd = TwistCmd(twist.surge_mps, twist.yaw_rate_radps, tick=tick, stamp_ns=stamp_ns)
        return self._keys.relative(self._keys.cmd_twist(vessel)), cmd
