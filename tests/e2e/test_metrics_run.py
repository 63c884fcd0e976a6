"""Navigation metrics through `catabot run`: a scripted collision, a scripted grounding and
a goal, each reported at the tick the recorded states show it, with the right bodies.

One run (module scope): `a` and `b` are driven head on at full thrust; `c` is driven at a
bank (water 10 m deep west of x = 100 m, land east of it) past its goal. Contact times are
read back from the recorded states: the first tick the hull boxes overlap or a bow probe is
below the bilinear ground (geometry), and the tick physics' contact force shows (a
deceleration no thruster can give). `d` starts upside down and floats so (a catamaran
is stable inverted): a capsize from the first state to the end."""

from __future__ import annotations

import csv
import json
import math
import subprocess
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from conftest import catabot, only_run_dir, scenario_file
from PIL import Image

TICK_S = 0.01
HALF_LENGTH = 0.95  # the catamaran's hull box, bow to origin
KEEL = -0.06
FULL = [{"t_s": 0.0, "thrust": [1.0, 1.0]}]
GOAL = {"x_m": 95.0, "y_m": 60.0, "radius_m": 1.5}


@pytest.fixture(scope="module")
def run(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, subprocess.CompletedProcess[str]]:
    tmp = tmp_path_factory.mktemp("metrics")
    image = np.zeros((80, 120), dtype=np.uint8)
    image[:, 100:] = 255  # 1 m pixels: -10 m (0) and +5 m (255)
    Image.fromarray(image).save(tmp / "bank.png")
    data = {
        "name": "metrics", "seed": 5, "duration_s": 8.0,
        "terrain": {"elevation_image": str(tmp / "bank.png"), "min_elevation_m": -10.0,
                    "max_elevation_m": 5.0, "metres_per_pixel": 1.0},
        "buoys": [{"id": "mark", "x_m": 26.0, "y_m": 24.0}],
        "vessels": [
            {"id": "a", "pose": {"x_m": 20.0, "y_m": 20.0, "yaw_rad": 0.0}, "script": FULL},
            {"id": "b", "pose": {"x_m": 32.0, "y_m": 20.0, "yaw_rad": math.pi}, "script": FULL},
            {"id": "c", "pose": {"x_m": 90.0, "y_m": 60.0}, "script": FULL,
             "task": {"goal": GOAL, "route": [[90.0, 61.0], [100.0, 61.0]]}},
            {"id": "d", "pose": {"x_m": 50.0, "y_m": 60.0, "roll_rad": 3.0}},  # capsized
        ],
        "recording": {"mcap": False},
    }  # fmt: skip
    out = tmp / "out"
    out.mkdir()
    result = catabot("run", str(scenario_file(tmp, data)), "--out", str(out), "--quiet")
    assert result.returncode == 0, result.stderr
    return only_run_dir(out), result


def _states(run_dir: Path, vessel: str) -> dict[str, np.ndarray]:
    with (run_dir / f"vessel.{vessel}.state.csv").open() as f:
        rows = list(csv.DictReader(f))
    return {
        "t": np.array([int(r["stamp_ns"]) for r in rows]) / 1e9,
        "x": np.array([float(r["position_x[m]"]) for r in rows]),
        "ax": np.array([float(r["linear_acceleration_x[m/s^2]"]) for r in rows]),
    }


def _metrics(run_dir: Path) -> dict[str, Any]:
    out: dict[str, Any] = json.loads((run_dir / "metrics.json").read_text())
    return out


def _counts(record: dict[str, Any], what: str) -> list[int]:
    """Each scenario vessel's count of `what` (traffic boats have none)."""
    return [v[what] for v in record["vessels"].values() if what in v]


def _first(mask: np.ndarray, t: np.ndarray) -> float:
    assert mask.any()
    return float(t[int(np.argmax(mask))])


def test_head_on_collision_at_the_contact_tick(run: tuple[Path, Any]) -> None:
    run_dir, _ = run
    a, b = _states(run_dir, "a"), _states(run_dir, "b")
    (hit,) = _metrics(run_dir)["collisions"]
    assert _metrics(run_dir)["end_reason"] == "completed"  # the figures cover the whole run
    assert (_metrics(run_dir)["scenario"], _metrics(run_dir)["seed"]) == ("metrics", 5)
    assert hit["bodies"] == ["a", "b"]
    overlap = _first(b["x"] - a["x"] <= 2 * HALF_LENGTH, a["t"])  # the boxes, along x
    pushed = _first(a["ax"] < -10.0, a["t"])  # thrust gives < 1 m/s^2
    assert abs(hit["start_s"] - overlap) <= 2 * TICK_S + 1e-9
    assert abs(hit["start_s"] - pushed) <= 2 * TICK_S + 1e-9
    assert hit["end_s"] is None  # still pushing each other at full thrust


def test_grounding_at_the_contact_tick(run: tuple[Path, Any]) -> None:
    run_dir, _ = run
    c = _states(run_dir, "c")
    record = _metrics(run_dir)
    (ground,) = record["groundings"]
    assert ground["vessel"] == "c"
    bank = 99.5 + (KEEL + 10.0) / 15.0  # the bilinear ground reaches the keel here
    touch = _first(c["x"] + HALF_LENGTH >= bank, c["t"])
    stopped = _first(c["ax"] < -10.0, c["t"])
    assert abs(ground["start_s"] - touch) <= 2 * TICK_S + 1e-9
    assert abs(ground["start_s"] - stopped) <= 2 * TICK_S + 1e-9
    assert _counts(record, "groundings") == [0, 0, 1, 0]
    shore = record["vessels"]["c"]["nearest_shore"]["distance_m"]
    assert shore == pytest.approx(100.5 - c["x"].max(), abs=1e-6)  # the first land pixel


def test_goal_cross_track_and_thrust_impulse(run: tuple[Path, Any]) -> None:
    run_dir, result = run
    c = _states(run_dir, "c")
    m = _metrics(run_dir)["vessels"]["c"]
    reached = _first(np.abs(c["x"] - GOAL["x_m"]) <= GOAL["radius_m"], c["t"])
    assert m["goal"]["reached"] and m["goal"]["time_to_goal_s"] == pytest.approx(reached)
    k = int(np.argmax(c["t"] >= reached))
    assert m["goal"]["path_length_m"] == pytest.approx(c["x"][k] - c["x"][0], abs=1e-3)
    assert m["route"]["max_cross_track_m"] == pytest.approx(1.0, abs=1e-3)  # 1 m beside it
    assert m["thrust_impulse_Ns"] == pytest.approx(2 * 36.0 * 8.0)  # full thrust, 8 s
    assert m["nearest_buoy"]["id"] == "mark" and m["collisions"] == 0
    assert "  c: goal reached at" in result.stdout and "groundings 1" in result.stdout


def test_a_vessel_upside_down_is_capsized_for_the_whole_run(run: tuple[Path, Any]) -> None:
    run_dir, result = run
    record = _metrics(run_dir)
    assert record["capsizes"] == [{"vessel": "d", "start_s": 0.0, "end_s": None}]  # its start
    assert record["vessels"]["d"]["max_tilt_rad"] > math.radians(150)
    assert _counts(record, "capsizes") == [0, 0, 0, 1]
    assert "groundings 0, capsizes 1" in result.stdout
