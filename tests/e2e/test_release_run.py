"""A scenario vessel taken over from outside and handed back (`catabot run`, a free client):
after the release physics follows the script's step in force again, and the thrust CSV's
last row is that step (it used to stay the outside command); a vessel with no script
rests again (the outside thrust used to stay on its thrusters)."""

from __future__ import annotations

import time
from pathlib import Path

import pytest
from conftest import csv_rows, only_run_dir, scenario_file, start

from catabot.bus.session import free_port
from catabot.client import Client, Thrust, Waypoints

pytestmark = pytest.mark.timeout(180)


def _thrust_rows(run: Path, vessel: str) -> list[tuple[int, tuple[float, float]]]:
    rows = csv_rows(run / f"vessel.{vessel}.cmd.thrust.csv")
    return [(int(r[1]), (float(r[2]), float(r[3]))) for r in rows[1:]]


def _surge(run: Path, vessel: str) -> list[float]:
    rows = csv_rows(run / f"vessel.{vessel}.state.csv")
    return [float(r[rows[0].index("linear_velocity_x[m/s]")]) for r in rows[1:]]


def test_a_released_vessel_follows_its_script_again_and_it_is_recorded(tmp_path: Path) -> None:
    endpoint, out = f"tcp/127.0.0.1:{free_port()}", tmp_path / "out"
    data = {"name": "release", "seed": 2, "duration_s": 8.0, "clock": {"realtime_factor": 2.0},
            "vessels": [{"id": "ego", "script": [{"t_s": 0.0, "thrust": [0.8, 0.8]}]},
                        {"id": "plain", "pose": {"x_m": 0.0, "y_m": 20.0}}]}  # fmt: skip
    proc = start("run", str(scenario_file(tmp_path, data)), "--quiet", "--out", str(out),
                 "--listen", endpoint)  # fmt: skip
    try:
        with Client.connect([endpoint], timeout_s=30) as sim:
            for vid in ("ego", "plain"):
                sim.vessel(vid).send(Thrust([-0.5, -0.5]))
            time.sleep(1.0)  # 2 s simulated astern
            for vid in ("ego", "plain"):
                sim.vessel(vid).send(Waypoints([], mode="release"))
        _, err = proc.communicate(timeout=120)
    finally:
        proc.kill()
    assert proc.returncode == 0, err
    run = only_run_dir(out)
    ego, plain = _thrust_rows(run, "ego"), _thrust_rows(run, "plain")
    assert [v for _, v in ego] == [(0.8, 0.8), (-0.5, -0.5), (0.8, 0.8)]
    assert [v for _, v in plain] == [(-0.5, -0.5), (0.0, 0.0)]
    assert _surge(run, "ego")[-1] > 1.0  # ahead again under its script
    surge = _surge(run, "plain")
    assert min(surge) < -0.3 and abs(surge[-1]) < 0.5 * abs(min(surge))  # coasting to rest
