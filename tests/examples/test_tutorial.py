"""docs/TUTORIAL.md's scenarios are what its text says: the first is valid, the shore mistake
is refused naming the nearest start deep enough, and with the controller of step 6 in place
of its script it is valid still (the program found from the repository's root)."""

from __future__ import annotations

import json
import re
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest

from catabot.run.cli import main
from tests.paths import REPO

TUTORIAL = REPO / "docs" / "TUTORIAL.md"


def tutorial_blocks() -> list[str]:
    return re.findall(r"```json\n(.*?)```", TUTORIAL.read_text(), re.S)


def first(tmp_path: Path, change: dict[str, Any] | None = None) -> Path:
    data = json.loads(tutorial_blocks()[0])
    data["vessels"][0] |= change or {}
    path = tmp_path / "first.json"
    path.write_text(json.dumps(data))
    return path


def test_the_first_scenario_is_valid(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["scenario", "validate", str(first(tmp_path))]) == 0
    assert "valid (1 vessel(s), 6 traffic boat(s)" in capsys.readouterr().out


def test_the_shore_mistake_names_the_nearest_start(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    ashore = first(tmp_path, {"pose": {"x_m": 300.0, "y_m": 520.0, "yaw_rad": 1.5708}})
    assert main(["scenario", "validate", str(ashore)]) == 2
    err = capsys.readouterr().err
    assert "vessels.0.pose (ego): start pose (300.0, 520.0) is on land" in err
    assert "the nearest start deep enough is (" in err


def test_step_6s_controller_runs_the_bundled_navigator(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    controller = json.loads("{" + tutorial_blocks()[1] + "}")
    path = first(tmp_path, controller)
    data = json.loads(path.read_text())
    del data["vessels"][0]["script"]
    path.write_text(json.dumps(data))
    monkeypatch.chdir(REPO)  # "every command runs from the repository's root"
    assert main(["scenario", "validate", str(path)]) == 0


def test_step_3s_summary_is_what_the_run_prints(tmp_path: Path) -> None:
    """The page quoted 29.52 s after the run had come to print 29.53 s: a reader checks it."""
    quoted = re.search(r"`(ego: goal reached at [\d.]+ s \([\d.]+ m\));", TUTORIAL.read_text())
    assert quoted is not None
    run = subprocess.run([sys.executable, "-m", "catabot", "run", str(first(tmp_path)),
                          "--duration", "30", "--quiet", "--out", str(tmp_path / "runs")],
                         capture_output=True, text=True, timeout=300)  # fmt: skip
    assert run.returncode == 0, run.stderr
    assert quoted.group(1) in run.stdout, run.stdout
