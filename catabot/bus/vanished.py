"""Whether a run's conductor has left the bus: a run killed outright sends no End, and an
observer (the ROS gateway's, the live view) learns of it only from the conductor's
liveliness token going. One watch for every observer."""

from __future__ import annotations

import time
from collections.abc import Callable

import zenoh

from catabot.bus.clock import CONDUCTOR
from catabot.bus.identity import Roster
from catabot.bus.keys import Keys
from catabot.bus.members import Members
from catabot.bus.session import linked


class ConductorWatch:
    """The conductor's token: only the roster's conductor counts, or the first one seen
    (members.py: another session's, a second run's or a stranger's, neither holds nor ends
    the watch), and only while this session is linked (its own link's drop takes every
    token away). `on_left`: called from Zenoh's thread when it goes."""

    def __init__(self, session: zenoh.Session, keys: Keys, roster: Roster,
                 on_left: Callable[[], None] | None = None) -> None:  # fmt: skip
        self._session, self._on_left = session, on_left
        self.members = Members(keys, Roster(roster.fixed))  # the caller's roster untouched
        self.left_at: float | None = None  # monotonic s
        self.subscriber = session.liveliness().declare_subscriber(
            keys.live(CONDUCTOR, "*"), self._on_token, history=True
        )

    def _on_token(self, sample: zenoh.Sample) -> None:
        alive = sample.kind == zenoh.SampleKind.PUT
        if self.members.token(str(sample.key_expr), alive=alive) != CONDUCTOR:
            return
        self.left_at = None if alive or not linked(self._session) else time.monotonic()
        if self.left_at is not None and self._on_left is not None:
            self._on_left()

    def gone(self, grace_s: float) -> bool:
        """Whether it left more than `grace_s` ago (its End, sent first, had time to come)."""
        left = self.left_at
        return left is not None and time.monotonic() - left > grace_s
