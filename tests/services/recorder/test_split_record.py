"""A split run's log/run.json, by its recorder (services/recorder/split_record.py): written
only where no launcher wrote one first, and a failed write does not end the recording."""

from __future__ import annotations

import json
import logging
from pathlib import Path

import pytest

from catabot.bus.messages import End
from catabot.config.load import parse_scenario
from services.recorder.split_record import SplitRecord

SCENARIO = parse_scenario({"name": "s", "seed": 3, "vessels": [{"id": "ego"}]})


def _record(run: Path) -> dict[str, object]:
    return dict(json.loads((run / "log" / "run.json").read_text()))


def test_without_a_launcher_the_recorder_writes_the_start_and_the_end(tmp_path: Path) -> None:
    account = SplitRecord(tmp_path, SCENARIO)
    started = _record(tmp_path)
    assert started["reason"] == "running" and "recorder_pid" in started and started["seed"] == 3
    account.end(End("r", 149, "fault", "participant 'physics' left the run"))
    ended = _record(tmp_path)
    assert (ended["reason"], ended["ticks"], ended["sim_s"]) == ("fault", 150, 1.5)
    assert ended["error"] == "participant 'physics' left the run"


def test_a_launchers_record_is_left_to_the_launcher(tmp_path: Path) -> None:
    (tmp_path / "log").mkdir()
    (tmp_path / "log" / "run.json").write_text('{"reason": "running", "launcher_pid": 7}\n')
    SplitRecord(tmp_path, SCENARIO).end(End("r", 9, "completed"))
    assert _record(tmp_path) == {"reason": "running", "launcher_pid": 7}


def test_a_record_that_cannot_be_written_is_said(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    account = SplitRecord(tmp_path, SCENARIO)
    (tmp_path / "log" / "run.json").unlink()
    (tmp_path / "log" / "run.json").mkdir()  # a folder where the file goes: the write fails
    with caplog.at_level(logging.ERROR):
        account.end(End("r", 9, "completed"))
    assert "cannot write" in caplog.text and "run.json" in caplog.text
