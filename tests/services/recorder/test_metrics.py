"""metrics.json from synthetic state batches: every figure against its analytic value."""

from __future__ import annotations

import dataclasses
import json
import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from catabot.bus.messages import BodyStates, Message, ThrustCmd, TwistCmd, WaypointsCmd
from catabot.config.load import parse_scenario
from catabot.world.orders import Orders
from catabot.world.world import World
from services.recorder.metrics import Metrics

DT = 10_000_000


def _world(**top: Any) -> World:
    data = {"name": "m", "vessels": [{"id": "v0", "pose": {"x_m": 0.0, "y_m": 0.0}},
                                     {"id": "v1", "pose": {"x_m": 0.0, "y_m": 10.0}}]}  # fmt: skip
    data |= top
    return World.resolve(parse_scenario(data))


def _states(world: World, tick: int, xy: list[tuple[float, float]], **kw: Any) -> BodyStates:
    n = len(world.body_ids)
    pos = np.zeros((n, 3))
    pos[:, :2] = xy
    yaw = np.asarray(kw.get("yaw", np.zeros(n)))
    quat = np.zeros((n, 4))
    quat[:, 2], quat[:, 3] = np.sin(yaw / 2), np.cos(yaw / 2)
    vel = np.tile([kw.get("speed", 0.0), 0.0, 0.0], (n, 1))
    z = np.zeros((n, 3))
    return BodyStates(tick, (tick + 1) * DT, world.body_ids, pos, quat, vel, z, z, z)


def _record(metrics: Metrics, tmp: Path) -> dict[str, Any]:
    metrics.write(tmp / "metrics.json")
    out: dict[str, Any] = json.loads((tmp / "metrics.json").read_text())
    return out


def test_distance_speed_and_closest_approach(tmp_path: Path) -> None:
    world = _world()
    metrics = Metrics(world, Orders())
    for tick in range(11):
        metrics.add(_states(world, tick, [(0.5 * tick, 0.0), (0.0, 10.0)], speed=0.1 * tick))
    record = _record(metrics, tmp_path)
    v0 = record["vessels"]["v0"]
    assert v0["distance_m"] == 5.0 and v0["final_position_m"] == [5.0, 0.0, 0.0]
    assert abs(v0["max_speed_mps"] - 1.0) < 1e-12
    assert record["closest_approach"] == {"distance_m": 10.0, "vessels": ["v0", "v1"],
                                          "stamp_ns": DT}  # fmt: skip
    assert v0["nearest_vessel"] == {"distance_m": 10.0, "id": "v1", "t_s": 0.01}
    assert v0["min_distance_m"] == {"v1": 10.0}
    assert v0["nearest_buoy"] is None and v0["nearest_shore"] is None
    assert record["sim_time_s"] == 0.11


def test_goal_time_path_length_and_cross_track(tmp_path: Path) -> None:
    task = {
        "goal": {"x_m": 10.0, "y_m": 0.0, "radius_m": 2.0},
        "route": [[0, -1], [20, -1], [20, 20]],
    }
    world = _world(vessels=[{"id": "v0", "pose": {"x_m": 0.0, "y_m": 0.0}, "task": task}])
    metrics = Metrics(world, Orders())
    for tick in range(100):  # 0.1 m a tick along y = 0: 1 m off the route's first leg
        metrics.add(_states(world, tick, [(0.1 * tick, 0.0)]))
    v0 = _record(metrics, tmp_path)["vessels"]["v0"]
    # inside the goal from x = 8 m: tick 80, stamped at the end of the tick
    assert v0["goal"] == {
        "reached": True,
        "time_to_goal_s": 0.81,
        "path_length_m": pytest.approx(8.0),
        "final_distance_m": pytest.approx(0.1),
    }
    assert v0["route"]["max_cross_track_m"] == pytest.approx(1.0)
    assert v0["route"]["rms_cross_track_m"] == pytest.approx(1.0)


def test_cross_track_of_a_corner_and_an_unreached_goal(tmp_path: Path) -> None:
    task = {
        "goal": {"x_m": 50.0, "y_m": 50.0, "radius_m": 1.0},
        "route": [[0, 0], [10, 0], [10, 10]],
    }
    world = _world(vessels=[{"id": "v0", "task": task, "pose": {"x_m": 0.0, "y_m": 0.0}}])
    metrics = Metrics(world, Orders())
    points = [(5.0, 3.0), (13.0, 5.0), (14.0, -3.0)]  # 3 m off each leg, 5 m off the corner
    for tick, p in enumerate(points):
        metrics.add(_states(world, tick, [p]))
    v0 = _record(metrics, tmp_path)["vessels"]["v0"]
    assert v0["route"]["max_cross_track_m"] == pytest.approx(5.0)
    assert v0["route"]["rms_cross_track_m"] == pytest.approx(math.sqrt((9 + 9 + 25) / 3))
    assert v0["goal"]["reached"] is False and v0["goal"]["time_to_goal_s"] is None
    assert v0["goal"]["final_distance_m"] == pytest.approx(math.hypot(36.0, 53.0))


def test_encounter_cpa_and_collision_of_a_head_on_pass(tmp_path: Path) -> None:
    """v1 comes head on at 1 m/tick, 0.5 m to the side: CPA 0.5 m when x meet; the hull
    boxes (1.9 m long) touch from a centre gap of 1.95 m on, and part after they pass."""
    world = _world(recording={"encounter_radius_m": 20.0})
    metrics = Metrics(world, Orders())
    yaw = np.array([0.0, math.pi])
    for tick in range(61):
        metrics.add(_states(world, tick, [(0.0, 0.0), (30.0 - tick, 0.5)], yaw=yaw))
    record = _record(metrics, tmp_path)
    (enc,) = record["encounters"]
    assert enc["vessels"] == ["v0", "v1"] and enc["cpa_m"] == pytest.approx(0.5)
    assert enc["cpa_s"] == pytest.approx(0.31)  # tick 30
    # within 20 m from x = 19 (tick 11) to x = -19 (tick 49): 20.006 m at x = +-20
    assert enc["start_s"] == pytest.approx(0.12) and enc["end_s"] == pytest.approx(0.50)
    (hit,) = record["collisions"]  # ticks 29..31 touch (gaps 1, 0, 1 m): one episode,
    assert hit == {"bodies": ["v0", "v1"], "start_s": 0.30, "end_s": None}  # apart < 1 s
    assert record["vessels"]["v0"]["collisions"] == 1 == record["vessels"]["v1"]["collisions"]


def test_rotated_hulls_collide_by_their_boxes(tmp_path: Path) -> None:
    """Side by side 1.2 m apart the beams (1.04 m) clear; turned across, the length reaches."""
    world = _world()
    for yaw, touching in ((0.0, False), (math.pi / 2, True)):
        metrics = Metrics(world, Orders())
        metrics.add(_states(world, 0, [(0.0, 0.0), (0.0, 1.2)], yaw=np.array([yaw, 0.0])))
        assert bool(_record(metrics, tmp_path)["collisions"]) is touching


def test_boxes_within_a_centimetre_touch(tmp_path: Path) -> None:
    """Side by side the beams (2 x 0.52 m) leave 5 mm (touching) or 20 mm (apart)."""
    world = _world()
    for y, touching in ((1.045, True), (1.06, False)):
        metrics = Metrics(world, Orders())
        metrics.add(_states(world, 0, [(0.0, 0.0), (0.0, y)]))
        assert bool(_record(metrics, tmp_path)["collisions"]) is touching


def test_buoys_are_nearest_and_can_be_hit(tmp_path: Path) -> None:
    buoys = [{"id": "far", "x_m": 50.0, "y_m": 0.0}, {"id": "near", "x_m": 5.0, "y_m": 0.0}]
    world = _world(vessels=[{"id": "v0", "pose": {"x_m": 0.0, "y_m": 0.0}}], buoys=buoys)
    metrics = Metrics(world, Orders())
    for tick in range(5):
        metrics.add(_states(world, tick, [(float(tick), 0.0), (50.0, 0.0), (5.0, 0.0)]))
    record = _record(metrics, tmp_path)
    assert record["vessels"]["v0"]["nearest_buoy"] == {"distance_m": 1.0, "id": "near", "t_s": 0.05}
    assert record["vessels"]["v0"]["min_distance_m"] == {"far": 46.0, "near": 1.0}
    assert [c["bodies"] for c in record["collisions"]] == [["v0", "near"]]
    assert record["collisions"][0]["start_s"] == 0.05  # 1.0 m < 0.95 + 0.22: overlapping


def _hear(orders: Orders, metrics: Metrics, msg: Message) -> None:
    """What the recorder does with a command for v0 (services/recorder/service.py)."""
    if orders.heard("v0", msg, stamp_ns=0):
        metrics.order_changed("v0")


def test_thrust_impulse_of_script_and_bus_commands(tmp_path: Path) -> None:
    script = [{"t_s": 0.0, "thrust": [0.5, -1.0]}, {"t_s": 0.1, "thrust": [1.0, 1.0]}]
    world = _world(vessels=[{"id": "v0", "script": script, "pose": {"x_m": 0.0, "y_m": 0.0}}])
    orders = Orders()
    metrics = Metrics(world, orders)
    for tick in range(30):
        if tick == 20:
            _hear(orders, metrics, ThrustCmd((0.0, 0.0)))
        if tick == 25:
            _hear(orders, metrics, TwistCmd(1.0, 0.0))
        metrics.add(_states(world, tick, [(0.0, 0.0)]))
    v0 = _record(metrics, tmp_path)["vessels"]["v0"]
    # 10 ticks at 0.5*36 + 1*28 = 46 N, 10 ticks at 72 N, then nothing; then 5 ticks unknown
    assert v0["thrust_impulse_Ns"] == pytest.approx(0.1 * 46 + 0.1 * 72)
    assert v0["thrust_unknown_s"] == 0.05  # exactly: ticks counted (summed, float noise)


def test_seconds_under_velocity_control_carry_no_float_noise(tmp_path: Path) -> None:
    """A trial's 30 s run said 29.990000000000155: spans of seconds summed at each change."""
    world = _world(vessels=[{"id": "v0", "pose": {"x_m": 0.0, "y_m": 0.0}}])
    orders = Orders()
    metrics = Metrics(world, orders)
    for tick in range(3000):
        if tick % 7 == 0:  # a stack's twist, repeated: each one settles the sums so far
            _hear(orders, metrics, TwistCmd(1.0 + tick % 2, 0.0))
        metrics.add(_states(world, tick, [(0.0, 0.0)]))
    unknown = _record(metrics, tmp_path)["vessels"]["v0"]["thrust_unknown_s"]
    assert unknown == round(unknown, 6) and 29.9 < unknown <= 30.0, unknown


def test_a_path_hands_an_outside_commands_vessel_back_to_its_script(tmp_path: Path) -> None:
    """As in physics: an outside thrust outranks the script until a WaypointsCmd."""
    script = [{"t_s": 0.0, "thrust": [1.0, 1.0]}]
    world = _world(vessels=[{"id": "v0", "script": script, "pose": {"x_m": 0.0, "y_m": 0.0}}])
    orders = Orders()
    metrics = Metrics(world, orders)
    for tick in range(30):
        if tick == 10:
            _hear(orders, metrics, ThrustCmd((0.0, 0.0)))
        if tick == 20:
            _hear(orders, metrics, WaypointsCmd((), 1.0, 1.0, "release"))
        metrics.add(_states(world, tick, [(0.0, 0.0)]))
    v0 = _record(metrics, tmp_path)["vessels"]["v0"]
    assert v0["thrust_impulse_Ns"] == pytest.approx(0.1 * 72 + 0.1 * 72)  # ticks 0-9, 20-29


def test_same_states_same_bytes(tmp_path: Path) -> None:
    world = _world(buoys=[{"id": "b", "x_m": 3.0, "y_m": 3.0}])
    outputs = []
    for name in ("a.json", "b.json"):
        metrics = Metrics(world, Orders())
        for tick in range(50):
            metrics.add(
                _states(world, tick, [(0.1 * tick, 0.0), (5.0 - 0.1 * tick, 1.0), (3.0, 3.0)])
            )
        metrics.write(tmp_path / name)
        outputs.append((tmp_path / name).read_bytes())
    assert outputs[0] == outputs[1]


def test_a_non_finite_batch_is_left_out(tmp_path: Path) -> None:
    world = _world()
    metrics = Metrics(world, Orders())
    metrics.add(_states(world, 0, [(0.0, 0.0), (0.0, 10.0)], speed=1.0))
    metrics.add(_states(world, 1, [(math.nan, 0.0), (0.0, 10.0)], speed=9.0))
    metrics.add(_states(world, 2, [(1.0, 0.0), (0.0, 10.0)], speed=1.0))
    metrics.write(tmp_path / "metrics.json")
    text = (tmp_path / "metrics.json").read_text()
    record = json.loads(text)
    assert "NaN" not in text and record["states_skipped"] == 1
    assert record["vessels"]["v0"]["distance_m"] == 1.0
    assert record["vessels"]["v0"]["max_speed_mps"] == 1.0


def test_a_vessel_over_on_its_side_capsized_and_righted(tmp_path: Path) -> None:
    """v0 rolls over to 180 deg and back by 5 deg a tick and stays upright beyond the episodes'
    1 s gap, v1 pitches to 30 deg: one capsize, from the first tilt past 90 deg to the last,
    and each one's largest tilt."""
    world = _world()
    metrics = Metrics(world, Orders())
    rolls = [*range(0, 181, 5), *range(175, -1, -5), *[0] * 120]
    for tick, deg in enumerate(rolls):
        batch = _states(world, tick, [(0.0, 0.0), (0.0, 10.0)])
        a, b = math.radians(deg) / 2, math.radians(min(tick, 30)) / 2
        quat = np.array(
            [[math.sin(a), 0.0, 0.0, math.cos(a)], [0.0, math.sin(b), 0.0, math.cos(b)]]
        )
        metrics.add(dataclasses.replace(batch, orientation=quat))
    record = _record(metrics, tmp_path)
    over = [t for t, deg in enumerate(rolls) if deg > 90]
    assert record["capsizes"] == [
        {"vessel": "v0", "start_s": (over[0] + 1) * DT / 1e9, "end_s": (over[-1] + 1) * DT / 1e9}
    ]
    v0, v1 = record["vessels"]["v0"], record["vessels"]["v1"]
    assert (v0["capsizes"], v1["capsizes"]) == (1, 0)
    assert v0["max_tilt_rad"] == pytest.approx(math.pi)
    assert v1["max_tilt_rad"] == pytest.approx(math.radians(30))


def test_distance_and_top_speed_are_over_the_ground(tmp_path: Path) -> None:
    """v0 heaves 1 m up and down at 2 m/s while it moves 0.5 m east; v1, pitched 30 deg bow
    up, makes 1 m/s along its deck: 0.87 m/s over the ground. A run's metrics had counted a
    boat dropped by a change of sea, still in the water, at 3.19 m/s."""
    world = _world()
    metrics = Metrics(world, Orders())
    half = math.radians(30) / 2
    for tick in range(11):
        batch = _states(world, tick, [(0.05 * tick, 0.0), (0.0, 10.0)])
        pos = np.array(batch.position)
        pos[0, 2] = 1.0 - abs(tick - 5) / 5  # up 1 m and down again
        quat = np.array([[0.0, 0.0, 0.0, 1.0], [0.0, -math.sin(half), 0.0, math.cos(half)]])
        vel = np.array([[0.0, 0.0, 2.0], [1.0, 0.0, 0.0]])
        metrics.add(dataclasses.replace(batch, position=pos, orientation=quat, linear_velocity=vel))
    v0, v1 = (_record(metrics, tmp_path)["vessels"][v] for v in ("v0", "v1"))
    assert v0["distance_m"] == pytest.approx(0.5) and v0["max_speed_mps"] == pytest.approx(0.0)
    assert v1["max_speed_mps"] == pytest.approx(math.cos(math.radians(30)))


def test_a_run_with_no_tick_writes_strict_json_with_every_key(tmp_path: Path) -> None:
    """A heat that ended at tick 0 wrote `"b1": Infinity` (Node refused the file) and left
    the `goal` key out, which a results script read in every other run."""
    goal = {"goal": {"x_m": 30.0, "y_m": 0.0, "radius_m": 2.0}}
    world = _world(vessels=[{"id": "v0", "task": goal}], buoys=[{"id": "b1", "x_m": 5, "y_m": 5}])
    metrics = Metrics(world, Orders())
    metrics.write(tmp_path / "metrics.json")
    text = (tmp_path / "metrics.json").read_text()
    data = json.loads(text, parse_constant=lambda c: pytest.fail(f"not JSON: {c}"))
    v0 = data["vessels"]["v0"]
    assert v0["min_distance_m"] == {"b1": None} and v0["goal"]["reached"] is False
    assert v0["goal"]["final_distance_m"] is None
