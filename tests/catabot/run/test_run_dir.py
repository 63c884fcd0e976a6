"""Run folders: `<name>-<time>`, each run its own even when many start in one second."""

from __future__ import annotations

import json
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import pytest

from catabot.config.load import parse_scenario
from catabot.run.cli import main
from catabot.run.ending import KILLED, end_reason, finished
from catabot.run.launcher import LaunchError, RunOptions, make_run_dir, prepare


def test_runs_started_together_each_get_their_own_folder(tmp_path: Path) -> None:
    """A check then a make let two runs race for one name: the loser exited 2."""
    scenario = parse_scenario({"name": "race", "vessels": [{"id": "ego"}]})
    out = tmp_path / "new" / "runs"  # made as needed
    with ThreadPoolExecutor(8) as pool:
        made = list(pool.map(lambda _: make_run_dir(out, scenario), range(16)))
    assert len(set(made)) == 16 and all((d / "scenario.json").is_file() for d in made)
    assert all(d.name.startswith("race-") for d in made)


def test_a_run_dir_given_is_the_run_folder_itself_new_or_empty(tmp_path: Path) -> None:
    """A sweep's script read the folder from stdout: --run-dir names it."""
    scenario = parse_scenario({"name": "exact", "vessels": [{"id": "ego"}]})
    made = make_run_dir(tmp_path / "runs", scenario, exact=tmp_path / "sweep" / "gain2")
    assert made == tmp_path / "sweep" / "gain2" and (made / "scenario.json").is_file()
    started = json.loads((made / "log" / "run.json").read_text())  # a kill -9 still says
    assert started["reason"] == "running" and started["scenario"] == "exact"
    assert {"started", "launcher_pid", "seed", "command", "git_commit"} <= started.keys()
    assert not finished(started) and end_reason(started, None) == KILLED
    assert end_reason(started, {"end_reason": "completed"}) == "completed"  # the recorder's
    with pytest.raises(LaunchError, match=r"--run-dir .*gain2: not empty; a run folder holds"):
        prepare(RunOptions(run_dir=made))
    (tmp_path / "file").write_text("x")
    with pytest.raises(LaunchError, match=r"--run-dir .*file: a file, not a folder"):
        prepare(RunOptions(run_dir=tmp_path / "file"))
    prepare(RunOptions(run_dir=tmp_path / "empty"))  # new: made when the run starts


def test_out_and_run_dir_together_are_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """--run-dir won and --out was dropped without a word."""
    argv = ["run", "--out", str(tmp_path / "a"), "--run-dir", str(tmp_path / "b" / "x")]
    assert main(argv) == 2
    assert "--out and --run-dir both name where the run goes: give one" in capsys.readouterr().err
    assert not (tmp_path / "a").exists() and not (tmp_path / "b").exists()
