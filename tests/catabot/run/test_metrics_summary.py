"""The metrics lines of `catabot run`'s summary, from metrics.json."""

from __future__ import annotations

import json
from pathlib import Path

from catabot.run.metrics_summary import metrics_lines

EGO = {
    "distance_m": 9.3, "max_speed_mps": 1.9, "final_position_m": [1, 2, 0],
    "nearest_vessel": {"distance_m": 1.891, "id": "b", "t_s": 4.0},
    "nearest_buoy": None, "nearest_shore": {"distance_m": 1.27, "t_s": 6.3},
    "goal": {"reached": True, "time_to_goal_s": 3.14, "path_length_m": 3.5,
             "final_distance_m": 4.2},
    "route": {"max_cross_track_m": 0.5, "rms_cross_track_m": 0.25},
    "collisions": 1, "groundings": 2, "thrust_impulse_Ns": 720.0, "thrust_unknown_s": 1.5,
}  # fmt: skip


def test_one_line_per_scenario_vessel(tmp_path: Path) -> None:
    boat = {"distance_m": 3.0, "max_speed_mps": 1.0, "final_position_m": [0, 0, 0]}
    record = {"vessels": {"ego": EGO, "boat_0": boat}}
    (tmp_path / "metrics.json").write_text(json.dumps(record))
    assert metrics_lines(tmp_path) == [
        "  ego: goal reached at 3.14 s (3.5 m); cross-track max 0.50 m, RMS 0.25 m; nearest "
        "vessel 1.89 m (b), shore 1.27 m; collisions 1, groundings 2; thrust impulse 720 N s "
        "(+1.5 s under velocity control)"
    ]


def test_goal_not_reached(tmp_path: Path) -> None:
    ego = EGO | {"goal": {"reached": False, "time_to_goal_s": None, "path_length_m": None,
                          "final_distance_m": 12.0}}  # fmt: skip
    (tmp_path / "metrics.json").write_text(json.dumps({"vessels": {"ego": ego}}))
    assert "goal not reached (12.0 m short)" in metrics_lines(tmp_path)[0]


def test_no_or_broken_metrics_print_nothing(tmp_path: Path) -> None:
    assert metrics_lines(tmp_path) == []
    (tmp_path / "metrics.json").write_text("{not json")
    assert metrics_lines(tmp_path) == []
    (tmp_path / "metrics.json").write_text("[1, 2]")
    assert metrics_lines(tmp_path) == []


def test_a_fleet_is_cut_short(tmp_path: Path) -> None:
    record = {"vessels": {f"v{k:02d}": EGO for k in range(20)}}
    (tmp_path / "metrics.json").write_text(json.dumps(record))
    lines = metrics_lines(tmp_path)
    assert len(lines) == 8 and lines[6].startswith("  v06: goal reached")
    assert lines[7] == f"  ... 13 more in {tmp_path / 'metrics.json'}"


def test_vessels_come_in_the_scenarios_order_not_the_files(tmp_path: Path) -> None:
    """metrics.json sorts its keys (for identical bytes): a swarm's leader came last."""
    record = {"vessels": {v: EGO for v in ("f1", "f2", "leader")}}
    (tmp_path / "metrics.json").write_text(json.dumps(record))
    order = ["leader", "f2", "f1"]  # the scenario's
    assert [line.split(":")[0] for line in metrics_lines(tmp_path, order)] == [
        "  leader",
        "  f2",
        "  f1",
    ]


def test_the_traffic_collisions_have_a_line_where_there_is_traffic(tmp_path: Path) -> None:
    boat = {"distance_m": 3.0, "max_speed_mps": 1.0, "final_position_m": [0, 0, 0]}
    hit = {"bodies": ["boat_0", "boat_1"], "start_s": 1.0, "end_s": 2.0}
    record = {"vessels": {"ego": EGO, "boat_0": boat}, "traffic_collisions": [hit, hit]}
    (tmp_path / "metrics.json").write_text(json.dumps(record))
    assert metrics_lines(tmp_path)[-1] == "  traffic: 2 collisions among its boats and buoys"
    (tmp_path / "metrics.json").write_text(json.dumps(record | {"traffic_collisions": [hit]}))
    assert metrics_lines(tmp_path)[-1] == "  traffic: 1 collision among its boats and buoys"
    alone = {"vessels": {"ego": EGO}, "traffic_collisions": []}
    (tmp_path / "metrics.json").write_text(json.dumps(alone))
    assert len(metrics_lines(tmp_path)) == 1  # no traffic: no line
