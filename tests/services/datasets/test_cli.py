"""`catabot dataset export` refused: one line, exit 2, and the output left as it was found."""

from __future__ import annotations

from pathlib import Path

import pytest

from catabot.config.load import load_scenario
from services.datasets import cli
from services.datasets.cli import main
from services.datasets.frames import ExportError


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
        (["--split-block-s", "0"], "--split-block-s must be > 0 and at most 9.2e+09 s (got 0.0)"),
        (["--split-block-s", "inf"], "--split-block-s must be > 0 and at most"),  # a traceback
        (["--min-visible", "1.5"], "--min-visible must be in [0, 1] (got 1.5)"),
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


@pytest.mark.parametrize("option", [["--val-fraction", "0.5"], ["--split-block-s", "5"]])
def test_a_split_asked_of_kitti_is_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], option: list[str]
) -> None:
    """KITTI's export puts every sequence in train: a split asked of it was taken silently."""
    out = tmp_path / "dataset"
    assert main(["export", str(tmp_path), "-f", "kitti", "-o", str(out), *option]) == 2
    err = capsys.readouterr().err
    assert f"{option[0]}: a kitti export is not split" in err and not out.exists()


def test_an_output_that_is_a_file_is_named_as_one(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    (tmp_path / "afile").write_text("")
    assert main(["export", str(tmp_path), "-f", "coco", "-o", str(tmp_path / "afile")]) == 2
    said = f"--output {tmp_path / 'afile'} is a file; give a folder (new or empty)"
    assert said in capsys.readouterr().err


def test_a_bad_format_is_one_line_too(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as info:
        main(["export", str(tmp_path), "--format", "voc", "-o", str(tmp_path / "o")])
    err = capsys.readouterr().err
    assert info.value.code == 2 and err.count("\n") == 1 and "usage:" not in err
    assert "invalid choice: 'voc'" in err


@pytest.mark.parametrize("existed", [False, True])
def test_a_failed_export_leaves_the_output_as_it_found_it(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, existed: bool
) -> None:
    """A half export (train written, val not) looked whole, and a second try was refused."""
    run = tmp_path / "run"
    run.mkdir()
    (run / "scenario.json").write_text(load_scenario().model_dump_json())
    out = tmp_path / "dataset"
    if existed:
        out.mkdir()

    def half(_run: object, folder: Path, _options: object) -> str:
        (folder / "train").mkdir()
        (folder / "train" / "0001.png").write_bytes(b"png")
        (folder / "annotations.json").write_text("{}")
        raise ExportError("frame 0002: no instance image")

    monkeypatch.setitem(cli.FORMATS, "coco", half)
    assert main(["export", str(run), "--format", "coco", "-o", str(out)]) == 2
    assert out.exists() == existed and (not existed or not any(out.iterdir()))
    monkeypatch.setitem(cli.FORMATS, "coco", lambda *_a, **_k: "0 images")
    assert main(["export", str(run), "--format", "coco", "-o", str(out)]) == 0  # try again
