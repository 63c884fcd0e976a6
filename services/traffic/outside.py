"""Paths sent to traffic boats from outside, said on the console as takeovers are.

Why: physics says when an outside thrust or twist takes a vessel over, but a path sent to a
boat (a `WaypointsCmd`) changed the run unsaid, and a 50 m/s path a boat cannot make passed
without a word (a hostile-client trial).
"""

from __future__ import annotations

import logging
from collections.abc import Sequence

from catabot.bus.messages import WaypointsCmd
from catabot.run.advice import advise, tell

log = logging.getLogger("traffic")


class OutsidePaths:
    """Which boats follow a path from outside, and at what speed."""

    def __init__(self, ids: Sequence[str], top_speed_mps: Sequence[float]) -> None:
        self.ids, self.top = tuple(ids), tuple(top_speed_mps)
        self.speed: dict[int, float] = {}  # boat row: its outside path's speed

    def taken(self, i: int, msg: WaypointsCmd, stamp_ns: int) -> None:
        """Boat `i` follows `msg`'s path from now: said when it was not on one before, and
        advised (once per speed) when the speed is beyond its full thrust."""
        vid = self.ids[i]
        if i not in self.speed:
            tell(log, f"{vid}: follows a path from outside from t = {stamp_ns / 1e9:g} s "
                      f"({len(msg.points) // 2} points, {msg.mode}, {msg.speed:g} m/s) until "
                      "a release")  # fmt: skip
        if msg.speed > self.top[i] and self.speed.get(i) != msg.speed:
            advise(log, f"{vid}: its path's speed {msg.speed:g} m/s is beyond its top speed, "
                        f"{self.top[i]:.2f} m/s at full thrust")  # fmt: skip
        self.speed[i] = msg.speed

    def released(self, i: int, stamp_ns: int) -> None:
        if self.speed.pop(i, None) is not None:
            tell(log, f"{self.ids[i]}: handed back to its scenario behaviour at "
                      f"t = {stamp_ns / 1e9:g} s")  # fmt: skip
