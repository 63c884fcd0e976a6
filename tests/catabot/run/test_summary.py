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


def test_a_start_that_failed_is_a_fault_and_the_services_stopped_after_it_are_not_blamed(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A stack that died before tick 0: run.json's reason was "" (a sweep testing for
    "fault" missed it) and every service stopped after it read as failed with 143."""
    (tmp_path / "log").mkdir()
    codes = {"physics": 143, "recorder": 143, "stack": 2}
    result = {"error": "stack: the program my.py ended (exit code 2)"}
    assert summarise(SCENARIO, tmp_path, result, 1, codes, after_fault={"physics", "recorder"})
    err = capsys.readouterr().err
    assert "physics: stopped by catabot run after the fault" in err
    assert "physics: exit code" not in err and "stack: exit code 2" in err
    assert json.loads((tmp_path / "log" / "run.json").read_text())["reason"] == "fault"


def test_run_json_says_what_produced_the_run(tmp_path: Path) -> None:
    """A sweep's table had to join three files to label a row with its seed, and nothing
    said which code or program produced the bytes."""
    program = tmp_path / "stack.py"
    program.write_text("print('hi')\n")
    scenario = parse_scenario({"name": "p", "seed": 7, "vessels": [{"id": "ego", "controller": {
        "participant": "stack", "program": str(program)}}]})  # fmt: skip
    (tmp_path / "log").mkdir()
    summarise(scenario, tmp_path, {"reason": "completed", "ticks_done": 1}, 0, {})
    record = json.loads((tmp_path / "log" / "run.json").read_text())
    assert (record["scenario"], record["seed"], record["command"][0]) == ("p", 7, "catabot")
    assert record["catabot_version"] == "0.1.0" and len(record["git_commit"]) in (0, 40, 46)
    digest = "2e4f7bf0a6ac1f19b2ba0a2dbfcaec4b7c6d3fe2f8a1b2a04b0bf3bb16b0c5b0"
    assert record["programs"]["stack"]["path"] == str(program)
    assert len(record["programs"]["stack"]["sha256"]) == len(digest)


def test_the_conductors_refusals_are_counted_in_the_file_its_console_line_names(
    tmp_path: Path,
) -> None:
    """A hostile trial looked for log/conductor.rejected.json, which the console named and
    nobody wrote: its counts came only in the result line."""
    counts = {"setting refused": 24, "malformed": 2}
    _end(tmp_path, {"physics": 0}, ticks_done=40, reason="completed", rejected=counts)
    written = json.loads((tmp_path / "log" / "conductor.rejected.json").read_text())
    assert written == {"malformed": 2, "setting refused": 24}
    assert json.loads((tmp_path / "log" / "run.json").read_text())["rejected"] == {
        "conductor": written
    }


def test_a_killed_conductor_is_told_by_its_last_progress_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """No result comes from a conductor killed outright: the summary said "0 ticks" of 800."""
    (tmp_path / "log").mkdir()
    progress = {"kind": "progress", "tick": 799, "stamp_ns": 8_000_000_000,
                "ticks_per_s": 400.0, "realtime_factor": 4.0}  # fmt: skip
    assert summarise(SCENARIO, tmp_path, {}, -9, {"physics": 143}, progress=progress) == 1
    assert capsys.readouterr().out.startswith("800 ticks, 8.00 s simulated in 2.00 s")
    record = json.loads((tmp_path / "log" / "run.json").read_text())
    assert record["ticks"] == 800 and "the conductor ended without a result" in record["error"]
