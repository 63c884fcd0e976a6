"""A participant's wait for its first tick: said every NOTE_EVERY_S, and checked against the
conductor's scenario.

Every Tick carries the digest of the conductor's scenario, so a process started on another
file stops at tick 0 (ClockLimits.check_digest). But a file that changes who takes part
(`traffic.shards` 2 on one host, 3 on the conductor's) leaves the conductor waiting for a
participant nobody starts, so no tick ever comes: the process given the other file waited
the conductor's whole start timeout (60 s by default) saying only that no tick came. At each
note it now asks the conductor's `world/info` for the digest; an answer from the
conductor's own session (a stranger's reply is ignored) that differs stops it at once.
"""

from __future__ import annotations

import json
import logging
import time
from typing import Any, Protocol

import zenoh

from catabot.bus.clock import CONDUCTOR
from catabot.bus.identity import Roster
from catabot.bus.keys import Keys
from catabot.bus.session import alone

log = logging.getLogger("catabot.bus.participant")
NOTE_EVERY_S = 10.0  # before tick 0, how often a participant says it still waits
NO_CLOCK = "; is its conductor on this router (--connect), or has its run ended?"
ASK_TIMEOUT_S = 5.0


class Sink(Protocol):
    """Where a digest that differs goes: the participant's events (lanes.py), or a queue."""

    def put(self, item: Any, /) -> None: ...


class StartWait:
    """A participant's side of the wait for tick 0 (its own thread calls `idle`)."""

    def __init__(
        self,
        session: zenoh.Session,
        keys: Keys,
        name: str,
        *,
        roster: Roster,
        events: Sink,
        digest: str,
    ) -> None:
        """`digest`: this process's scenario's ("" asks nothing); a conductor's that is
        another goes to the participant's `events` as ("digest", "", digest, "")."""
        self.session, self.keys, self.name, self.roster = session, keys, name, roster
        self.events, self.digest = events, digest
        self.since, self.notes = time.monotonic(), 0

    def idle(self, present: set[str]) -> None:
        """No grant yet and nothing heard for a while: every NOTE_EVERY_S, say so and ask."""
        waited = time.monotonic() - self.since  # said nothing, however long
        if waited <= NOTE_EVERY_S * (self.notes + 1):
            return
        self.notes += 1
        log.warning("%s: no tick from the conductor of world %r after %.0f s (present: %s)%s",
                    self.name, self.keys.world, waited, sorted(present),
                    alone(self.session) or NO_CLOCK)  # fmt: skip
        self._ask()

    def _ask(self) -> None:
        conductor = self.roster.zid(CONDUCTOR)
        if not self.digest or conductor is None:
            return

        def on_reply(reply: zenoh.Reply) -> None:
            replier = reply.replier_id  # an entity of a session: the conductor's own?
            if reply.ok is not None and replier is not None and str(replier.zid) == conductor:
                theirs = digest_in(reply.ok.payload.to_bytes())
                if theirs and theirs != self.digest:
                    self.events.put(("digest", "", theirs.encode(), ""))

        self.session.get(
            self.keys.world_info(),
            on_reply,
            timeout=ASK_TIMEOUT_S,
            target=zenoh.QueryTarget.ALL,
            consolidation=zenoh.ConsolidationMode.NONE,
        )  # a stranger's hides none


def digest_in(payload: bytes) -> str:
    """The scenario digest of a `world/info` answer ("" if it has none)."""
    try:
        digest = json.loads(payload)["clock"]["digest"]
    except (ValueError, TypeError, KeyError):
        return ""
    return digest if isinstance(digest, str) else ""
