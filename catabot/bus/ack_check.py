"""Which acks the conductor believes (conductor.py): one from the session whose liveliness
token names its participant, decoded, of this run and a real tick, with printable reasons.

Why apart: an ack is how a run advances, so one a stranger could forge would step it (or end
it); every rule an ack must pass is here in one place, and anything else is a `Rejected` the
conductor counts and drops.
"""

from __future__ import annotations

from collections.abc import Container

import zenoh

from catabot.bus import clock, codec
from catabot.bus.identity import sender_of, shown
from catabot.bus.keys import Keys
from catabot.bus.members import Members
from catabot.bus.messages import Ack
from catabot.bus.rejections import Rejected


def checked_ack(
    key: str,
    sample: zenoh.Sample,
    *,
    keys: Keys,
    members: Members,
    expected: Container[str],
    run_id: str,
) -> tuple[str, Ack]:
    """The participant an ack on `key` is from, and the ack; Rejected if not believed."""
    name = keys.participant_of(key)
    if name not in expected:
        raise Rejected("ack of no participant", name)
    if not members.sender_is(name, sender_of(sample)):
        raise Rejected("ack from a stranger", shown(sender_of(sample)))
    try:
        ack = codec.decode(sample.payload.to_bytes(), Ack)
    except codec.CodecError as exc:
        raise Rejected("malformed", str(exc)) from None
    if ack.run != run_id or ack.tick < -1:
        raise Rejected("ack of another run or tick", f"run {ack.run}, tick {ack.tick}")
    for text, what in ((ack.end, "end request"), (ack.fault, "fault")):
        if text and clock.end_reason_problem(text):
            raise Rejected(f"{what} with a bad reason", clock.end_reason_problem(text))
    return name, ack
