"""A recorded run folder (catabot/run/recorded.py, recorded_camera.py): how it ended, as
every tool reports it, and its labelled frames read from a file cut short."""

from __future__ import annotations

import json
from pathlib import Path
from types import SimpleNamespace

import pytest

from catabot.run.recorded import RecordedRun, RunFolderError
from catabot.run.recorded_camera import labelled_frames


def _folder(tmp: Path, metrics: dict[str, str] | None) -> RecordedRun:
    scenario = {"name": "r", "duration_s": 30.0, "vessels": [{"id": "ego"}]}
    (tmp / "scenario.json").write_text(json.dumps(scenario))
    if metrics is not None:
        (tmp / "metrics.json").write_text(json.dumps(metrics))
    return RecordedRun(tmp)


def test_an_interrupted_or_killed_run_says_so(tmp_path: Path) -> None:
    """report.html read an interrupted run as a whole one ("simulated 4.84 s" of 30, no word
    why); a dataset export of one said nothing either."""
    for name, metrics, said in [
        ("a", {"end_reason": "interrupted"}, "interrupted, of 30 s planned"),
        ("b", {"end_reason": "completed"}, "completed"),
        ("c", None, "killed (log/run.json has no ending), of 30 s planned"),
    ]:
        (tmp_path / name).mkdir()
        assert _folder(tmp_path / name, metrics).ended() == said


def test_a_labels_file_cut_mid_line_gives_its_whole_frames(tmp_path: Path) -> None:
    """A run killed while writing labels.jsonl: its whole lines are read (as run.mcap's
    whole records are), where one cut line refused the whole export. A bad line that is not
    the last is still refused by its number."""
    camera = SimpleNamespace(vessel="ego", config=SimpleNamespace(name="cam"))
    folder = tmp_path / "dataset" / "ego.cam"
    folder.mkdir(parents=True)
    lines = [json.dumps({"tick": t, "stamp_ns": t * 10**7}) for t in (40, 20)]
    (folder / "labels.jsonl").write_text("\n".join(lines) + '\n{"tick": 6')
    frames = labelled_frames(tmp_path, camera)  # type: ignore[arg-type]
    assert [f.tick for f in frames] == [20, 40]
    (folder / "labels.jsonl").write_text('{"tick": 6\n' + "\n".join(lines) + "\n")
    with pytest.raises(RunFolderError, match=r"labels.jsonl:1: not a JSON line"):
        labelled_frames(tmp_path, camera)  # type: ignore[arg-type]
    (folder / "labels.jsonl").write_text('{"tick": 6')  # cut with no whole frame: said
    with pytest.raises(RunFolderError, match=r"labels.jsonl:1: not a JSON line"):
        labelled_frames(tmp_path, camera)  # type: ignore[arg-type]
