"""The recorder's run folder holds this run's scenario.json (services/recorder/service.py)."""

from __future__ import annotations

import logging
from pathlib import Path

import pytest

from catabot.config.load import parse_scenario
from services.recorder.service import _own_scenario


def test_a_folder_used_again_gets_this_runs_scenario_and_says_so(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    """Split services given one --run-dir twice (a compose file's fixed folder) kept the
    first run's scenario.json: plot drew the second run's states against it, or refused."""
    first = parse_scenario({"name": "w", "vessels": [{"id": "ego"}], "traffic": {"count": 8}})
    second = parse_scenario({"name": "w", "vessels": [{"id": "ego", "pose": {"x_m": 5.0}}]})
    _own_scenario(tmp_path, first)
    (tmp_path / "vessel.boat_000.state.csv").write_text("stamp_ns,tick\n")
    with caplog.at_level(logging.WARNING):
        _own_scenario(tmp_path, first)  # the same run's scenario: left as it is, not told
        assert caplog.records == []
        _own_scenario(tmp_path, second)
    assert (tmp_path / "scenario.json").read_text() == second.model_dump_json(indent=2) + "\n"
    (said,) = [r.getMessage() for r in caplog.records]
    assert (
        f"{tmp_path} held another run's scenario.json: replaced with this run's; the 1 CSV" in said
    )
