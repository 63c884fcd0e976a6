"""Helpers for end-to-end tests: real `catabot run` processes over real Zenoh."""

from __future__ import annotations

import json
import subprocess
import sys
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import pytest

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


def matched_publisher(session: Any, key: str) -> Any:
    """A publisher on `key` once the run's subscribers have matched it (a put before that
    reaches nobody)."""
    pub = session.declare_publisher(key)
    for _ in range(100):
        if pub.matching_status.matching:
            break
        time.sleep(0.05)
    time.sleep(0.5)  # matching means one subscriber (the recorder); let physics match too
    return pub
