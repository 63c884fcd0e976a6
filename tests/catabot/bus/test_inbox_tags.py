"""A clocked stream's tags in order: a sample past the next due tag is refused."""

from __future__ import annotations

import pytest

from catabot.bus.rejections import Rejected
from tests.catabot.bus.inbox_samples import GPS, STATE, _add, _gps, _inbox, _state


def test_a_sample_that_skips_a_due_tag_is_refused() -> None:
    """A hostile trial put states for ticks ahead, with physics' copied source info: taken,
    they made physics' own samples for the ticks between late, and their rows were lost.
    A producer sends every due tag in order, so a tag past the next due one is refused."""
    inbox = _inbox()
    _add(inbox, STATE, _state(0))
    with pytest.raises(Rejected, match=r"tag skips ahead: tick 5 before tick 1 \(period 1\)"):
        _add(inbox, STATE, _state(5))
    _add(inbox, STATE, _state(1))  # the producer's own, still taken
    inbox.switch(STATE, 2, on=False)  # switched off from tag 2 to tag 7
    inbox.switch(STATE, 7, on=True)
    _add(inbox, STATE, _state(7))  # the tags it was off at are not skipped
    with pytest.raises(Rejected, match="tag skips ahead: tick 9 before tick 8"):
        _add(inbox, STATE, _state(9))


def test_what_a_run_ended_without_names_each_stream_and_its_last_tag() -> None:
    """After a lost link the recorder said "run ended without samples from [imu]", which
    read as no IMU at all: it was the last tick's, in flight when the link went."""
    inbox = _inbox()
    for tick in range(4):
        _add(inbox, STATE, _state(tick))
    _add(inbox, GPS, _gps(0))
    assert inbox.unarrived(4) == ""
    assert inbox.unarrived(6) == f"{STATE} from 'physics' after its tick 3"
    both = f"{STATE} from 'physics' after its tick 3; {GPS} from 'sensors' after its tick 0"
    assert inbox.unarrived(12) == both


def test_a_wildcard_put_is_refused_once_by_whoever_watches_every_key_under_it() -> None:
    """A put on `vessel/*/cmd/thrust` reached each stream under it and physics' watch over
    every command key: counted twice, under two reasons. A watch that speaks for it (strays.py)
    takes it; with none, each stream refuses it, saying it was a wildcard."""
    inbox, wild = _inbox(), f"{STATE.rsplit('/', 2)[0]}/*/state"
    with pytest.raises(Rejected, match=r"not a stream key: '.*\*/state': a put on a key exp"):
        inbox.add(wild, b"\x80", sender="x")
    inbox.spoken_for = lambda key: key == wild
    inbox.add(wild, b"\x80", sender="x")  # left to the watch: no refusal here
    with pytest.raises(Rejected, match=r"not a stream key: 'elsewhere'$"):
        inbox.add("elsewhere", b"\x80", sender="x")  # no wildcard: this inbox's to refuse
