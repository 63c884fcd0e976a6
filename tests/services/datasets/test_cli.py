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


@pytest.mark.parametrize(
    ("option", "why"),
    [
        (["--val-fraction", "1.5"], "--val-fraction must be in [0, 1] (got 1.5)"),
        (["--split-block-s", "0"], "--split-block-s must be > 0 (got 0.0)"),
        ([], "exists and is not an empty folder"),
    ],
)
def test_a_bad_option_is_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], option: list[str], why: str
) -> None:
    out = tmp_path / "dataset"
    out.mkdir()
    (out / "taken").write_text("")
    argv = ["export", str(tmp_path), "--format", "coco", "-o", str(out), *option]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and why in err and "usage" not in err
