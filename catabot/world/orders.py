"""Which command a vessel follows: the one precedence rule (DESIGN.md §4), written once for
physics, which applies it, and the recorder, which writes and meters what physics applied.

An outside command (a thrust or a twist at tick -1) takes a vessel over until a
`WaypointsCmd` hands it back; a lockstep set-point (a controller's twist at tick >= 0, or a
traffic boat's row of the traffic's batch) steers it from the first one on; otherwise it
follows its script: outside > lockstep set-point > script, the step in force (`script_step`),
or rest before its first. Commands reach here checked (catabot/bus/checks.py).
"""

from __future__ import annotations

import bisect
import functools
from collections.abc import Sequence

from catabot.bus.messages import Message, ThrustCmd, TwistCmd, WaypointsCmd
from catabot.config.scenario import ScriptStep

Order = ThrustCmd | TwistCmd


class Orders:
    """The commands from the bus in force, by vessel (a script is the vessels' own)."""

    def __init__(self) -> None:
        self.held: dict[str, Order] = {}  # by an outside command, until handed back
        self.steered: dict[str, TwistCmd] = {}  # by lockstep set-points, for good

    def heard(self, vessel: str, msg: Message) -> bool:
        """Take one command for `vessel`; whether the rule could have changed its order
        (a release of a vessel nobody held changes nothing)."""
        if isinstance(msg, WaypointsCmd):
            return self.held.pop(vessel, None) is not None
        if isinstance(msg, TwistCmd) and msg.tick >= 0:
            self.steered[vessel] = msg
        elif isinstance(msg, ThrustCmd | TwistCmd):
            self.held[vessel] = msg
        else:
            return False
        return True

    def in_force(self, vessel: str) -> Order | None:
        """The bus's command `vessel` follows now; None while it follows its script."""
        held = self.held.get(vessel)
        return held if held is not None else self.steered.get(vessel)

    def follows_script(self, vessel: str) -> bool:
        return vessel not in self.held and vessel not in self.steered


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
