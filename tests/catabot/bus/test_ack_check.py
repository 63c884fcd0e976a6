"""Which acks the conductor believes (catabot/bus/ack_check.py): every rule an ack must pass,
each refusal by name. The live paths (a stranger's ack, a forged end) are in test_hostile."""

from __future__ import annotations

from types import SimpleNamespace
from typing import Any

import pytest

from catabot.bus import codec
from catabot.bus.ack_check import checked_ack
from catabot.bus.identity import Roster
from catabot.bus.keys import Keys
from catabot.bus.members import Members
from catabot.bus.messages import Ack
from catabot.bus.rejections import Rejected

KEYS = Keys("w")
ZID = "a1b2c3"


def _sample(payload: bytes, sender: str = ZID) -> Any:
    info = SimpleNamespace(source_id=SimpleNamespace(zid=sender))
    return SimpleNamespace(payload=SimpleNamespace(to_bytes=lambda: payload), source_info=info)


def _check(payload: bytes, *, sender: str = ZID, name: str = "physics") -> tuple[str, Ack]:
    members = Members(KEYS, Roster({"physics": ZID}))
    return checked_ack(KEYS.ack(name), _sample(payload, sender), keys=KEYS, members=members,
                       expected={"physics"}, run_id="run1")  # fmt: skip


def test_an_ack_of_its_participants_session_is_believed() -> None:
    name, ack = _check(codec.encode(Ack("run1", 4, end="episode over")))
    assert (name, ack.tick, ack.end) == ("physics", 4, "episode over")


@pytest.mark.parametrize(
    ("payload", "sender", "name", "refusal"),
    [
        (Ack("run1", 4), ZID, "sensors", "ack of no participant"),
        (Ack("run1", 4), "ffff", "physics", "ack from a stranger"),
        (b"\x81\xa1x", ZID, "physics", "malformed"),
        (Ack("run0", 4), ZID, "physics", "ack of another run or tick"),
        (Ack("run1", -2), ZID, "physics", "ack of another run or tick"),
        (Ack("run1", 4, end="two\nlines"), ZID, "physics", "end request with a bad reason"),
        (Ack("run1", 4, fault="x" * 201), ZID, "physics", "fault with a bad reason"),
    ],
)
def test_every_other_ack_is_refused_by_name(
    payload: Ack | bytes, sender: str, name: str, refusal: str
) -> None:
    data = payload if isinstance(payload, bytes) else codec.encode(payload)
    with pytest.raises(Rejected) as caught:
        _check(data, sender=sender, name=name)
    assert caught.value.reason == refusal
