"""Which command a vessel follows: the one precedence rule (DESIGN.md §4), written once for
physics, which applies it, and the recorder, which writes and meters what physics applied.

An outside command (a thrust or a twist at tick -1) takes a vessel over until a
`WaypointsCmd` hands it back; a lockstep set-point (a controller's twist at tick >= 0, or a
traffic boat's row of the traffic's batch) steers it from the first one on; otherwise it
follows its script: outside > lockstep set-point > script. Commands reach here checked
(catabot/bus/checks.py).
"""

from __future__ import annotations

from catabot.bus.messages import Message, ThrustCmd, TwistCmd, WaypointsCmd

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
