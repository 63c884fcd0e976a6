"""metrics.json: distance, speed, final position and closest approach from the state batches."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from catabot.bus.messages import BodyStates
from services.recorder.metrics import Metrics


def _batch(tick: int, xs: list[float], speed: float) -> BodyStates:
    n = len(xs)
    pos = np.array([[x, 10.0 * k, 0.0] for k, x in enumerate(xs)])
    vel = np.tile([speed, 0.0, 0.0], (n, 1))
    zero, quat = np.zeros((n, 3)), np.tile([0.0, 0.0, 0.0, 1.0], (n, 1))
    ids = (*(f"v{k}" for k in range(n - 1)), "buoy")
    return BodyStates(tick, (tick + 1) * 10, ids, pos, quat, vel, zero, zero, zero)


def test_distance_speed_and_closest_approach(tmp_path: Path) -> None:
    metrics = Metrics(["v0", "v1"])  # the buoy row after them is ignored
    for tick in range(11):
        metrics.add(_batch(tick, [0.5 * tick, 0.0, 1000.0], speed=0.1 * tick))
    metrics.write(tmp_path / "metrics.json")
    record = json.loads((tmp_path / "metrics.json").read_text())
    v0 = record["vessels"]["v0"]
    assert v0["distance_m"] == 5.0 and v0["final_position_m"] == [5.0, 0.0, 0.0]
    assert abs(v0["max_speed_mps"] - 1.0) < 1e-12
    assert record["closest_approach"] == {
        "distance_m": 10.0,
        "vessels": ["v0", "v1"],
        "stamp_ns": 10,
    }
    assert record["sim_time_s"] == 110e-9


def test_single_vessel_has_no_closest_approach(tmp_path: Path) -> None:
    metrics = Metrics(["v0"])
    metrics.add(_batch(0, [0.0, 5.0], speed=0.0))
    metrics.write(tmp_path / "m.json")
    assert json.loads((tmp_path / "m.json").read_text())["closest_approach"] is None
