"""Which command a vessel follows: the one precedence rule (DESIGN.md §4), written once for
physics, which applies it, and the recorder, which writes and meters what physics applied.

An outside command (a thrust or a twist at tick -1) takes a vessel over until a
`WaypointsCmd` hands it back, or, with the vessel's `command_timeout_s`, until no outside
command has come for that long (a stack that died stops steering it, as an autopilot drops
a stale set-point); a lockstep set-point (a controller's twist at tick >= 0, or a
traffic boat's row of the traffic's batch) steers it from the first one on; otherwise it
follows its script: outside > lockstep set-point > script, the step in force (`script_step`),
or rest before its first. Commands reach here checked (catabot/bus/checks.py).
"""

from __future__ import annotations

import bisect
import functools
from collections.abc import Mapping, Sequence

from catabot.bus.clock import NS_PER_S
from catabot.bus.messages import Message, ThrustCmd, TwistCmd, WaypointsCmd
from catabot.config.scenario import ScriptStep
from catabot.world.world import Body

Order = ThrustCmd | TwistCmd


class Orders:
    """The commands from the bus in force, by vessel (a script is the vessels' own).
    `timeouts`: each vessel's command_timeout_s in ns, for those that have one."""

    def __init__(self, timeouts: Mapping[str, int] | None = None) -> None:
        self.held: dict[str, Order] = {}  # by an outside command, until handed back
        self.steered: dict[str, TwistCmd] = {}  # by lockstep set-points, for good
        self.timeouts = dict(timeouts or {})
        self.held_since: dict[str, int] = {}  # the stamp of the tick that took the last

    def heard(self, vessel: str, msg: Message, *, stamp_ns: int) -> bool:
        """Take one command for `vessel`, taken at the tick stamped `stamp_ns`; whether the
        rule could have changed its order (a release of a vessel nobody held changes
        nothing)."""
        if isinstance(msg, WaypointsCmd):
            return self.held.pop(vessel, None) is not None
        if isinstance(msg, TwistCmd) and msg.tick >= 0:
            self.steered[vessel] = msg
        elif isinstance(msg, ThrustCmd | TwistCmd):
            self.held[vessel] = msg
            self.held_since[vessel] = stamp_ns
        else:
            return False
        return True

    def drop(self, vessel: str) -> None:
        """Its controller left the run and the run goes on without it (clock.policy drop):
        its last lockstep command or set-point no longer holds it (a crashed stack's boat
        sailed on at its last speed to the end); an outside command still does."""
        self.steered.pop(vessel, None)
        if vessel in self.held and self.held[vessel].tick >= 0:
            del self.held[vessel]

    def expire(self, stamp_ns: int) -> list[str]:
        """At the tick stamped `stamp_ns`, after its commands were heard: hand back every
        vessel whose outside command (tick -1; a lockstep one is renewed by the clock) is
        `timeouts` old; the vessels handed back."""
        stale = [v for v, cmd in self.held.items() if cmd.tick < 0 and v in self.timeouts
                 and stamp_ns - self.held_since[v] >= self.timeouts[v]]  # fmt: skip
        for vessel in stale:
            del self.held[vessel]
        return stale

    def in_force(self, vessel: str) -> Order | None:
        """The bus's command `vessel` follows now; None while it follows its script."""
        held = self.held.get(vessel)
        return held if held is not None else self.steered.get(vessel)

    def follows_script(self, vessel: str) -> bool:
        return vessel not in self.held and vessel not in self.steered


def command_timeouts(bodies: Sequence[Body]) -> dict[str, int]:
    """Each vessel's `command_timeout_s` in ns, for those that have one."""
    return {b.id: round(b.command_timeout_s * NS_PER_S) for b in bodies
            if b.command_timeout_s is not None}  # fmt: skip


def script_step(
    script: Sequence[ScriptStep], script_ns: Sequence[int], thrusters: int, stamp_ns: int
) -> ScriptStep:
    """The step of a script (in time order, its times `script_ns`) in force at `stamp_ns`,
    or rest before its first: what a vessel no command holds follows (after a release the
    outside thrust stayed on). Physics applies it; the recorder writes it."""
    index = bisect.bisect_right(script_ns, stamp_ns) - 1
    return script[index] if index >= 0 else _rest(thrusters)


@functools.lru_cache(maxsize=16)
def _rest(thrusters: int) -> ScriptStep:
    return ScriptStep(t_s=0.0, thrust=[0.0] * thrusters)
