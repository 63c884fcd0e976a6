"""The lockstep's start (catabot/bus/conductor.py): who the conductor waits for, who never
came, and who came and went before tick 0."""

from __future__ import annotations

import logging
import threading
import time

import pytest

from catabot.bus import clock, conductor
from tests.catabot.bus.lockstep_world import World


def test_the_conductor_says_who_it_waits_for(
    world: World, monkeypatch: pytest.MonkeyPatch, caplog: pytest.LogCaptureFixture
) -> None:
    """Started by hand (a service per machine), it named them only at the timeout."""
    monkeypatch.setattr(conductor, "WAITING_NOTE_S", 0.3)
    world.member("here")
    with caplog.at_level(logging.INFO, logger="catabot.bus.conductor"):
        result = world.run(["here", "ghost"], 10, deadline_s=1.0, start_timeout_s=1.0)
    assert "never joined" in result.error
    notes = [r.getMessage() for r in caplog.records if "waiting for" in r.getMessage()]
    assert notes and all(n.startswith("waiting for ghost to join (") for n in notes)


def test_a_participant_that_never_joins_is_named(world: World) -> None:
    world.member("here")
    t0 = time.monotonic()
    result = world.run(["here", "ghost"], 10, deadline_s=1.0, start_timeout_s=0.5)
    assert time.monotonic() - t0 < 3.0
    assert "never joined" in result.error
    assert "ghost" in result.error and "here" not in result.error
    assert "0.5 s" in result.error
    assert result.ticks_done == 0
    here = world.members["here"]
    here.join()
    assert here.ticks == []
    assert here.end is not None and here.end.error == result.error


def test_one_that_joined_and_left_before_the_start_is_said_so(world: World) -> None:
    """A stack that crashed after its join was reported as never joined, 60 s later."""
    world.member("here")
    gone = world.open()
    token = gone.liveliness().declare_token(world.keys.live("gone", str(gone.zid())))
    threading.Timer(0.3, token.undeclare).start()  # its process ended before the start
    result = world.run(["here", "gone", "late"], 10, deadline_s=1.0, start_timeout_s=1.5)
    assert result.error == (
        "participant(s) never joined within 1.5 s: gone, late (gone joined, then left before "
        "the start: ended?)"
    )  # "late" never came: the run had not started when "gone" left
    assert clock.who_never_joined(result.error) == ["gone", "late"]
    world.members["here"].join()
