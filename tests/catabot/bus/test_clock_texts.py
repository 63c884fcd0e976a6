"""The clock's texts that other processes read back (catabot/bus/clock.py): each is built by
one function and read by its pair, so the format lives in one place."""

from __future__ import annotations

from catabot.bus.clock import (
    end_reason,
    end_reason_problem,
    ended_by,
    ender_of,
    never_joined,
    who_never_joined,
)

TIMEOUT = never_joined(["recorder", "sensors"], 60.0)


def _unseen(name: str, error: str) -> bool:
    return name in who_never_joined(error)


def test_a_service_the_conductor_never_saw_is_named_by_the_start_timeout() -> None:
    """Logged in as another process (secure profile), it exited 0 and its log was empty."""
    assert TIMEOUT == "participant(s) never joined within 60 s: recorder, sensors"
    assert _unseen("sensors", TIMEOUT) and _unseen("recorder", TIMEOUT)
    assert not _unseen("physics", TIMEOUT)  # it joined: another's failure, not its own
    assert not _unseen("sensors", "participant 'sensors' left the run at tick 4")
    assert not _unseen("sensors", "")


def test_who_ended_the_run_is_read_back_from_the_end_reason() -> None:
    reason = ended_by("stack", 2779, "goal reached: 'mark' 2")
    assert reason == "ended by 'stack' after tick 2779: goal reached: 'mark' 2"
    assert ender_of(reason) == "stack"
    assert ender_of("completed") is None and ender_of("interrupted") is None
    assert ender_of("fault") is None


def test_an_end_reason_is_1_to_200_printable_characters() -> None:
    assert end_reason_problem("goal reached") == ""
    for bad in ("", "x" * 201, "tab\there", "bell\x07"):
        assert "1-200 printable characters" in end_reason_problem(bad)


def test_any_text_a_step_ends_with_becomes_a_valid_reason() -> None:
    assert end_reason("line one\nline two") == "line one line two"
    assert len(end_reason("x" * 500)) == 200 and end_reason("") == "no reason given"
