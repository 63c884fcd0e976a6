"""A sweep as a user runs one: `catabot run --set` into one folder, then `catabot results`
over it (the table of each run's swept field and outcome, and a CSV for pandas)."""

from __future__ import annotations

from pathlib import Path

import pandas as pd
import pytest
from conftest import catabot, scenario_file

pytestmark = pytest.mark.timeout(180)

TASK = '{"goal": {"x_m": 3.0, "y_m": 0.0, "radius_m": 1.5}}'


def test_a_sweep_over_a_thrust_tabulates_each_runs_outcome(tmp_path: Path) -> None:
    data = {"name": "sweep", "seed": 4, "duration_s": 3.0,
            "vessels": [{"id": "ego", "script": [{"t_s": 0.0, "thrust": [0.8, 0.8]}]},
                        {"id": "moored", "pose": {"x_m": 0.0, "y_m": 30.0}}]}  # fmt: skip
    path, out = scenario_file(tmp_path, data), tmp_path / "sweep"
    for thrust in ("[0.8, 0.8]", "[0.1, 0.1]"):
        run = catabot("run", str(path), "--quiet", "--out", str(out),
                      "--set", f"vessels.0.script.0.thrust={thrust}",
                      "--set", f"vessels.0.task={TASK}")  # fmt: skip
        assert run.returncode == 0, run.stderr
    table = catabot("results", str(out), "--csv", str(tmp_path / "sweep.csv"))
    assert table.returncode == 0, table.stderr
    lines = table.stdout.splitlines()
    thrust = ["vessels.0.script.0.thrust.0", "vessels.0.script.0.thrust.1"]  # an item each
    assert lines[0].split()[:4] == ["run", "vessel", *thrust]
    assert lines[-1] == f"2 runs, 4 rows; every column in {tmp_path / 'sweep.csv'}"
    rows = pd.read_csv(tmp_path / "sweep.csv")
    assert rows["vessel"].tolist() == ["ego", "moored"] * 2
    for column in thrust:
        assert rows[column].tolist() == [0.8] * 2 + [0.1] * 2  # numbers, not JSON text
    ego = rows[rows["vessel"] == "ego"].reset_index()
    assert ego["goal_reached"].tolist() == [True, False]  # full thrust gets there in 3 s
    assert ego["time_to_goal_s"][0] < 3.0 and ego["final_distance_m"][1] > 1.5
    assert ego["distance_m"][0] > 2 * ego["distance_m"][1]
    assert (rows["reason"] == "completed").all() and (rows["sim_s"] == 3.0).all()
    assert rows["nearest_vessel"].tolist() == ["moored", "ego"] * 2
