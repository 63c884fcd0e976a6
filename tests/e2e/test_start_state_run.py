"""A vessel started off rest (pose z, roll; a body-frame velocity) in a real run: the first
recorded state is the start itself (tick -1, t = 0), the next one tick on from it."""

from __future__ import annotations

import math
from pathlib import Path

import pytest
from conftest import basic_scenario, catabot, csv_rows, only_run_dir, scenario_file


def test_the_first_recorded_state_follows_from_the_start(tmp_path: Path) -> None:
    data = basic_scenario("start", duration_s=0.05)
    data["vessels"][0] = {
        "id": "ego",
        "pose": {"x_m": 0.0, "y_m": 0.0, "z_m": 0.2, "roll_rad": 0.1},
        "velocity": {"surge_mps": 1.5},
    }
    out = tmp_path / "out"
    result = catabot("run", str(scenario_file(tmp_path, data)), "--out", str(out), "--quiet")
    assert result.returncode == 0, result.stderr
    header, start, first, *_ = csv_rows(only_run_dir(out) / "vessel.ego.state.csv")
    at_start = dict(zip(header, map(float, start), strict=True))
    assert (at_start["tick"], at_start["stamp_ns"], at_start["position_z[m]"]) == (-1, 0, 0.2)
    assert at_start["linear_velocity_x[m/s]"] == 1.5  # the start itself, as given
    row = dict(zip(header, map(float, first), strict=True))
    assert row["tick"] == 0
    assert row["linear_velocity_x[m/s]"] == pytest.approx(1.5, rel=0.02)
    assert row["position_x[m]"] == pytest.approx(0.015, rel=0.02)
    assert row["position_z[m]"] == pytest.approx(0.2, abs=0.005)  # falling from 20 cm up
    assert row["orientation_x"] == pytest.approx(math.sin(0.05), abs=1e-3)  # rolled 0.1 rad
