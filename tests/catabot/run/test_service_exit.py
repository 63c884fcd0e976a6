"""How a service reads the run's end for its exit status (catabot/run/service.py)."""

from __future__ import annotations

from catabot.run.service import _unseen

TIMEOUT = "participant(s) never joined within 60 s: recorder, sensors"


def test_a_service_the_conductor_never_saw_is_named_by_the_start_timeout() -> None:
    """Logged in as another process (secure profile), it exited 0 and its log was empty."""
    assert _unseen("sensors", TIMEOUT) and _unseen("recorder", TIMEOUT)
    assert not _unseen("physics", TIMEOUT)  # it joined: another's failure, not its own
    assert not _unseen("sensors", "participant 'sensors' left the run at tick 4")
    assert not _unseen("sensors", "")
