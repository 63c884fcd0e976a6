"""Puts a participant hears on no stream of its own: a command to a vessel that does not
exist reached no subscriber, and nobody said so. Physics watches `vessel/*/cmd/*` with this
and names the unknown vessel or command (counted and logged like any refused sample)."""

from __future__ import annotations

from collections.abc import Callable

import zenoh

from catabot.bus.identity import sender_of
from catabot.bus.inbox import WILDCARD
from catabot.bus.participant import Participant


def watch_strays(participant: Participant, pattern: str, why: Callable[[str], str]) -> None:
    """Refuse, by `why(key)`, puts under `pattern` on no stream of `participant`."""
    known = frozenset(participant.inbox.keys)
    events = participant.events
    watched = zenoh.KeyExpr(pattern)

    def on_sample(sample: zenoh.Sample) -> None:
        key = str(sample.key_expr)
        if key not in known:  # the streams' own samples: a set lookup, nothing queued
            events.offer("stray", key, sender_of(sample), 0, lambda: _reason(key))  # lanes.py

    def _reason(key: str) -> bytes:  # worked out only for a stray its sender's lane takes
        return (shape_problem(key, pattern) or why(key)).encode()

    participant.keep(participant.session.declare_subscriber(pattern, on_sample))
    # only now, the watch declared: a wildcard put the inbox leaves to it is heard by it
    participant.inbox.spoken_for = lambda key: watched.intersects(zenoh.KeyExpr(key))


def shape_problem(key: str, pattern: str) -> str:
    """Why `key` is no key of `pattern`'s form ("" if it is): a put on a wildcard expression
    (`vessel/**`) reaches the subscriber as that expression, of any depth, and `why` reads
    a key's segments (a hostile client's put made physics log a traceback per sample)."""
    if "*" in key:
        return f"{WILDCARD} ({pattern})"
    if key.count("/") != pattern.count("/"):
        return f"not a key of the form {pattern}"
    return ""
