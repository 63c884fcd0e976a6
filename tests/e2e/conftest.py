"""Helpers for end-to-end tests: real `catabot run` processes over real Zenoh."""

from __future__ import annotations

import json
import subprocess
import sys
import threading
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import pytest

from catabot.run.cli import main
from tests.paths import REPO

pytestmark = pytest.mark.timeout(120)


def catabot(
    *args: str, timeout: float = 180, cwd: Path | None = None
) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "catabot", *args],
        capture_output=True,
        text=True,
        timeout=timeout,
        cwd=cwd or REPO,
    )


def start(*args: str) -> subprocess.Popen[str]:
    return subprocess.Popen(
        [sys.executable, "-m", "catabot", *args],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        cwd=REPO,
    )


def scenario_file(folder: Path, data: dict[str, Any], name: str = "scenario.json") -> Path:
    path = folder / name
    path.write_text(json.dumps(data))
    return path


def basic_scenario(name: str = "e2e", **top: Any) -> dict[str, Any]:
    vessel = {"id": "ego", "script": [{"t_s": 0.5, "thrust": [0.6, 0.8]}]}
    return {"name": name, "seed": 3, "duration_s": 3.0, "vessels": [vessel], **top}


def only_run_dir(out: Path) -> Path:
    runs = sorted(p for p in out.iterdir() if p.is_dir())
    assert len(runs) == 1, runs
    return runs[0]


def csv_rows(path: Path) -> list[list[str]]:
    lines = path.read_text().splitlines()
    return [line.split(",") for line in lines]


def service_pid(launcher_pid: int, module: str) -> int:
    import psutil

    for child in psutil.Process(launcher_pid).children(recursive=True):
        if module in " ".join(child.cmdline()):
            return int(child.pid)
    raise LookupError(module)


def wait_for_line(proc: subprocess.Popen[str], needle: str, limit: int = 50) -> str:
    assert proc.stdout is not None
    for _ in range(limit):
        line = proc.stdout.readline()
        if needle in line:
            return line
    raise AssertionError(f"{needle!r} never printed")


@pytest.fixture
def out(tmp_path: Path) -> Path:
    folder = tmp_path / "runs"
    folder.mkdir()
    return folder


def files_of(
    run_dir: Path, patterns: Sequence[str] = ("*.csv", "*.mcap", "metrics.json")
) -> dict[str, bytes]:
    return {p.name: p.read_bytes() for pat in patterns for p in sorted(run_dir.glob(pat))}


def matched_publisher(session: Any, key: str, *, timeout: float = 60.0) -> Any:
    """A publisher on `key` once the run is stepping: a world state means every participant
    joined, and each declares its subscribers before it joins, so no put is lost to a
    service still starting (a fixed wait was not enough on a loaded machine)."""
    pub = session.declare_publisher(key)
    world = key.split("/")[1]
    stepping = threading.Event()
    sub = session.declare_subscriber(f"catabot/{world}/vessel/*/state", lambda _s: stepping.set())
    try:
        if not stepping.wait(timeout):
            raise TimeoutError(f"no vessel state on catabot/{world} within {timeout} s")
    finally:
        sub.undeclare()
    return pub


VIZ_SECONDS = 2.0


def _viz_scenario() -> dict[str, Any]:
    """Every sensor, traffic, a buoy and rain, recorded with run.rrd and every export."""
    data = basic_scenario("viz", duration_s=VIZ_SECONDS)
    data["vessels"][0]["pose"] = {"x_m": 0.0, "y_m": 0.0}
    data["vessels"][0]["sensors"] = [
        {"name": "cam", "type": "camera", "rate_hz": 5.0, "params": {"width": 160, "height": 120}},
        {"name": "lidar", "type": "lidar", "rate_hz": 10.0,
         "params": {"channels": 16, "columns": 256}},
        {"name": "radar", "type": "radar", "rate_hz": 20.0, "params": {"rotation_period_s": 0.5}},
        {"name": "imu", "type": "imu", "rate_hz": 50.0},
    ]  # fmt: skip
    data["vessels"].append({"id": "other", "pose": {"x_m": 30.0, "y_m": 1.0}})
    data["buoys"] = [{"id": "b1", "x_m": 25.0, "y_m": -6.0}]
    data["traffic"] = {"count": 2, "behaviour_mix": {"circle": 1.0}}
    data["rain"] = {"rate_mm_h": 20.0}
    data["recording"] = {"rerun": True, "export": ["yolo", "coco", "kitti", "segmentation"]}
    return data


@pytest.fixture(scope="session")
def viz_run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """One recorded run that the viewer, plot and dataset tests all read (once a worker)."""
    tmp = tmp_path_factory.mktemp("viz")
    out = tmp / "runs"
    out.mkdir()
    result = catabot("run", str(scenario_file(tmp, _viz_scenario())), "--out", str(out), "--quiet")
    assert result.returncode == 0, result.stdout + result.stderr
    (tmp / "console.txt").write_text(result.stdout)
    return only_run_dir(out)


def in_process(args: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[int, str, str]:
    """`catabot ARGS` run by main in this process (a tool's refusal needs no start-up of
    its own): its exit code, argparse's own exits too, and what it printed."""
    try:
        code = main(args)
    except SystemExit as exit_:
        code = exit_.code if isinstance(exit_.code, int) else 1
    said = capsys.readouterr()
    return code, said.out, said.err
