"""Twist set-points beyond a vessel's thrusters, told to the user once per vessel.

The velocity controller clamps to the thrusters' limits (control.py), so a surge and yaw
rate the vessel cannot hold settles short without an error: a stack that asks the
catamaran for 1 m/s in a 0.3 rad/s turn gets 0.58 m/s. Physics compares each vessel's
first such order (scripted, or from the bus) with the thrust its steady state needs under
the model's damping law and says how far the thrusters reach: straight ahead, astern and
turning in place. Where a combined set-point settles also depends on terms that law leaves
out (the catamaran turns at 0.29 rad/s, not 0.27, once under way), so no figure is promised.
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Sequence

import numpy as np

from catabot.bus.messages import Message, TwistCmd
from catabot.run.advice import advise
from catabot.world.world import Body
from services.physics.control import TwistController

log = logging.getLogger("physics.reach")
BISECTIONS = 30  # a part in 1e9 of the range searched
MAX_SURGE, MAX_YAW_RATE = 100.0, 100.0  # m/s, rad/s: where the search for a top speed starts


class Reach:
    def __init__(self, vessels: Sequence[Body], controllers: Sequence[TwistController]) -> None:
        """`controllers`: each vessel's, in the same order (TwistControllerBank.single)."""
        self.control = {v.id: c for v, c in zip(vessels, controllers, strict=True)}
        self.told: set[str] = set()
        for v in vessels:
            for step in v.script:
                if step.twist is not None:
                    self.check(v.id, step.twist.surge_mps, step.twist.yaw_rate_radps, "scripted")

    def heard(self, vessel: str, msgs: list[Message]) -> None:
        for msg in msgs:
            if isinstance(msg, TwistCmd):
                self.check(vessel, msg.surge, msg.yaw_rate, "commanded")

    def check(self, vessel: str, surge: float, yaw_rate: float, how: str) -> None:
        if vessel in self.told or not self.beyond(vessel, surge, yaw_rate):
            return
        self.told.add(vessel)
        ahead = _most(lambda x: not self.beyond(vessel, x, 0.0), MAX_SURGE)
        astern = _most(lambda x: not self.beyond(vessel, -x, 0.0), MAX_SURGE)
        around = _most(lambda x: not self.beyond(vessel, 0.0, x), MAX_YAW_RATE)
        reach = (f"about {ahead:.2f} m/s straight ahead, {astern:.2f} m/s astern, "
                 f"{around:.2f} rad/s turning in place")  # fmt: skip
        alone = abs(surge) <= (ahead if surge >= 0 else astern) and abs(yaw_rate) <= around
        both = " together: a turn takes thrust from the speed" if alone else ""
        advise(log, f"{vessel}: the {how} twist {surge:g} m/s at {yaw_rate:g} rad/s is beyond "
                    f"its thrusters{both} (they hold {reach}), so it settles short of it: "
                    "compare the recorded state with the twist (said once a vessel)")  # fmt: skip

    def beyond(self, vessel: str, surge: float, yaw_rate: float) -> bool:
        """Whether holding the set-point in steady state needs more than the thrusters give:
        more force than they have, or a force they cannot make at all (one thruster on the
        centreline turns nothing: its yaw request had vanished without a word)."""
        control = self.control[vessel]
        wrench = control.feed_forward(np.array([surge, yaw_rate]))
        forces, scaled = control.allocate(wrench)
        made = control.alloc @ forces
        return scaled or not np.allclose(made, wrench, rtol=1e-6, atol=1e-6)


def _most(holds: Callable[[float], bool], goal: float) -> float:
    """The largest f * goal, 0 <= f <= 1, that `holds` (it holds at 0), by bisection."""
    if holds(goal):
        return goal
    lo, hi = 0.0, 1.0
    for _ in range(BISECTIONS):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if holds(mid * goal) else (lo, mid)
    return lo * goal
