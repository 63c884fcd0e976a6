"""How a run's end is told (catabot/run/summary.py): who is blamed when Ctrl-C comes early."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from catabot.config.load import parse_scenario
from catabot.run.service import EXIT_CLOCK
from catabot.run.summary import summarise

SCENARIO = parse_scenario({"name": "s", "vessels": [{"id": "ego"}]})
INTERRUPTED = {"reason": "interrupted", "ticks_done": 0, "wall_s": 0.5}


def _end(tmp_path: Path, codes: dict[str, int | None], **result: object) -> int:
    (tmp_path / "log").mkdir(exist_ok=True)
    return summarise(SCENARIO, tmp_path, {**INTERRUPTED, **result}, 130, codes)


def test_a_service_that_lost_the_stopped_conductor_is_not_blamed(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Ctrl-C while starting: the recorder saw the conductor go before it was stopped."""
    assert _end(tmp_path, {"physics": 0, "recorder": EXIT_CLOCK}) == 130
    err = capsys.readouterr().err
    assert "run failed" not in err and "recorder: stopped by catabot run" in err
    assert json.loads((tmp_path / "log" / "run.json").read_text())["ticks"] == 0


def test_a_real_failure_or_a_lost_clock_once_ticking_is_still_blamed(tmp_path: Path) -> None:
    assert _end(tmp_path, {"recorder": 2}) == 1  # its own error, not the interrupt
    assert _end(tmp_path, {"recorder": EXIT_CLOCK}, ticks_done=40) == 1  # the run had started
