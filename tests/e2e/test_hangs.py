"""Every process of a run stopped (SIGSTOP: hung) or killed (SIGKILL): `catabot run` names it
truthfully and returns within the deadline plus two seconds, with readable files."""

from __future__ import annotations

import os
import signal
import time
from pathlib import Path

import psutil
import pytest
from conftest import csv_rows, only_run_dir, scenario_file, start, wait_for_line

DEADLINE_S = 3.0
PROCESSES = ["conductor", "physics", "sensors", "traffic", "recorder"]
MODULES = {"conductor": "catabot.run.conduct", **{n: f"services.{n}" for n in PROCESSES[1:]}}


def _scenario(tmp: Path) -> Path:
    data = {
        "name": "hangs", "duration_s": 600.0,
        "clock": {"realtime_factor": 2.0, "deadline_s": DEADLINE_S},
        "vessels": [{"id": "ego", "script": [{"t_s": 0.5, "thrust": [0.6, 0.8]}],
                     "sensors": [{"name": "imu", "type": "imu", "rate_hz": 50.0}]}],
        "traffic": {"count": 1},
    }  # fmt: skip
    return scenario_file(tmp, data)


def _pid(launcher: int, module: str) -> int:
    for child in psutil.Process(launcher).children(recursive=True):
        if module in " ".join(child.cmdline()):
            return int(child.pid)
    raise LookupError(module)


def _wait_for_rows(out: Path, rows: int, limit_s: float = 30.0) -> None:
    end = time.monotonic() + limit_s
    while time.monotonic() < end:
        states = list(out.glob("*/vessel.ego.state.csv"))
        if states and len(states[0].read_bytes().splitlines()) > rows:
            return
        time.sleep(0.1)
    logs = {p.name: p.read_text()[-2000:] for p in out.glob("*/log/*.log")}
    raise AssertionError(f"no {rows} states recorded in {limit_s} s; logs: {logs}")


@pytest.mark.parametrize("how", [signal.SIGSTOP, signal.SIGKILL], ids=["stop", "kill"])
@pytest.mark.parametrize("name", PROCESSES)
def test_a_stopped_or_killed_process_is_named_within_the_deadline(
    tmp_path: Path, out: Path, name: str, how: signal.Signals
) -> None:
    proc = start("run", str(_scenario(tmp_path)), "--out", str(out), "--quiet")
    wait_for_line(proc, "zenoh:")
    _wait_for_rows(out, 20)
    children = psutil.Process(proc.pid).children(recursive=True)
    os.kill(_pid(proc.pid, MODULES[name]), how)
    hit = time.monotonic()
    _, err = proc.communicate(timeout=60)
    took = time.monotonic() - hit
    assert proc.returncode == 1, err
    assert took < DEADLINE_S + 2.0, f"returned {took:.1f} s after the {how.name}"
    failure = next(line for line in err.splitlines() if line.startswith("run failed:"))
    if how is signal.SIGSTOP:
        assert "hung" in failure and name in failure, failure
    else:
        assert name in failure or (name == "conductor" and "SIGKILL" in failure), failure
    assert not [c for c in children if c.is_running() and c.status() != psutil.STATUS_ZOMBIE]
    rows = csv_rows(only_run_dir(out) / "vessel.ego.state.csv")
    assert all(len(r) == len(rows[0]) for r in rows), "a CSV row is torn"
