"""`catabot dataset export` refused: one line, exit 2, and no empty output folder left."""

from __future__ import annotations

from pathlib import Path

import pytest

from catabot.config.load import load_scenario
from services.datasets.cli import main


def test_a_run_without_a_camera_is_refused_and_leaves_no_folder(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    run = tmp_path / "run"
    run.mkdir()
    (run / "scenario.json").write_text(load_scenario().model_dump_json())  # no camera in it
    out = tmp_path / "dataset"
    assert main(["export", str(run), "--format", "yolo", "-o", str(out)]) == 2
    assert "no labelled camera frames" in capsys.readouterr().err
    assert not out.exists()
