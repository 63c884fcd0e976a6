"""The recorder's run folder holds this run alone (services/recorder/service.py)."""

from __future__ import annotations

from pathlib import Path

import pytest

from catabot.config.load import parse_scenario
from catabot.config.scenario import Scenario
from services.recorder.csv_sink import RecorderError
from services.recorder.service import _fresh_folder

FIRST = parse_scenario({"name": "w", "vessels": [{"id": "ego"}], "traffic": {"count": 8}})
SECOND = parse_scenario({"name": "w", "vessels": [{"id": "ego", "pose": {"x_m": 5.0}}]})


@pytest.mark.parametrize("scenario", [FIRST, SECOND], ids=["same scenario", "another"])
def test_a_folder_holding_a_recording_is_refused_and_left_as_it_is(
    tmp_path: Path, scenario: Scenario
) -> None:
    """Split services given one --run-dir twice (a compose file's fixed folder) mixed two
    runs in it: the second's run.mcap and metrics.json beside the first's CSVs, and nothing
    said when both had the same scenario."""
    _fresh_folder(tmp_path, FIRST)
    for name in ("vessel.ego.state.csv", "run.mcap", "metrics.json"):
        (tmp_path / name).write_text("the first run's")
    (tmp_path / "dataset").mkdir()
    with pytest.raises(RecorderError) as refused:
        _fresh_folder(tmp_path, scenario)
    assert str(refused.value) == (
        f"run folder {tmp_path} already holds a recording (dataset, metrics.json, run.mcap, "
        "vessel.ego.state.csv): give this run a folder of its own (--run-dir; compose: "
        "CATABOT_RUN=<name>) or move those away"
    )
    assert (tmp_path / "scenario.json").read_text() == FIRST.model_dump_json(indent=2) + "\n"
    assert (tmp_path / "run.mcap").read_text() == "the first run's"


def test_a_scenario_and_logs_alone_are_not_a_recording(tmp_path: Path) -> None:
    """What `catabot run` writes before its recorder starts, or a run that never recorded."""
    _fresh_folder(tmp_path, FIRST)
    (tmp_path / "log").mkdir()
    (tmp_path / "log" / "physics.log").write_text("")
    _fresh_folder(tmp_path, SECOND)
    assert (tmp_path / "scenario.json").read_text() == SECOND.model_dump_json(indent=2) + "\n"
