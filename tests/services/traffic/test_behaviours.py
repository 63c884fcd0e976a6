"""Traffic behaviours driving real PhysicsWorld boats, and the spawning plan."""

from __future__ import annotations

import math

import numpy as np
import pytest

from catabot.config.load import parse_scenario
from catabot.config.scenario import Pose
from catabot.config.traffic import TrafficConfig
from catabot.config.vessel import load_vessel_model
from catabot.world.placement import footprint_m, scenario_models
from catabot.world.terrain import Terrain
from catabot.world.traffic_plan import Boat, Planner
from catabot.world.world import World
from services.physics.control import TwistControllerBank
from services.physics.world import PhysicsWorld
from services.traffic.behaviours import Behaviours

DT = 0.01  # physics' default tick
GUIDANCE = round(1 / (TrafficConfig().guidance_hz * DT))  # ticks between set-points


def _simulate(
    boats: list[Boat], seconds: float, *, period: int = GUIDANCE, delay: int = 0
) -> np.ndarray:
    """Boats stepped in PhysicsWorld under their behaviours, as in a run: set-points every
    `period` ticks, applied `delay` ticks late and held; returns positions (steps, N, 2)."""
    model = load_vessel_model("monohull")
    starts = [(b.id, model, (b.pose.x_m, b.pose.y_m, 0.0, b.pose.yaw_rad)) for b in boats]
    world = PhysicsWorld(starts, dt_s=DT)
    bank = TwistControllerBank([model] * len(boats), dt_s=DT)
    behaviours = Behaviours(boats)
    rows = np.arange(len(boats))
    pending = [np.zeros((len(boats), 2))] * (delay + 1)  # set-points on their way
    track = []
    for k in range(round(seconds / DT)):
        s = world.state_arrays()
        if k % period == 0:
            q = s.orientation
            yaw = np.arctan2(
                2 * (q[:, 3] * q[:, 2] + q[:, 0] * q[:, 1]), 1 - 2 * (q[:, 1] ** 2 + q[:, 2] ** 2)
            )
            surge, rate = behaviours.command(s.position[:, :2], yaw, s.linear_velocity)
            latest = np.stack([surge, rate], axis=1)
        pending.append(latest)
        target = pending.pop(0)
        measured = np.stack([s.linear_velocity[:, 0], s.angular_velocity[:, 2]], axis=1)
        out = bank.command(rows, target, measured)
        for i, b in enumerate(boats):
            world.set_thrust(b.id, out[i])
        world.step()
        track.append(world.state_arrays().position[:, :2])
    return np.array(track)


def _circler(offset_m: float = 0.0, yaw: float = 0.0) -> tuple[Boat, float]:
    radius = 5.0 / math.radians(15.0)  # the original's 5 m/s at 15 deg/s
    pose = Pose(x_m=0.0, y_m=-radius - offset_m, yaw_rad=yaw)
    return Boat("b", "monohull", pose, "circle", 5.0, (0.0, 0.0), radius, 1), radius


def test_circling_boat_holds_its_radius_within_5_percent() -> None:
    boat, radius = _circler()
    track = _simulate([boat], 60.0)
    steady = track[len(track) // 2 :, 0]
    r = np.hypot(steady[:, 0], steady[:, 1])
    assert np.abs(r / radius - 1).max() < 0.05, (r.min(), r.max(), radius)
    angle = np.unwrap(np.arctan2(steady[:, 1], steady[:, 0]))
    assert angle[-1] > angle[0] + math.pi  # counter-clockwise, and really going round


@pytest.mark.parametrize(
    ("offset_m", "yaw", "period", "delay"),
    [(60.0, 0.0, GUIDANCE, 0), (-15.0, 0.0, GUIDANCE, 0), (30.0, 3.0, GUIDANCE, 0),
     (-15.0, 0.0, 1, 0), (-15.0, 0.0, GUIDANCE, 4)],
)  # fmt: skip
def test_a_boat_off_its_circle_joins_it_without_oscillating(
    offset_m: float, yaw: float, period: int, delay: int
) -> None:
    """From outside, inside, or heading away; set-points every tick or held, even late:
    within 5% of the radius in 25 s and within 1% for the last 10 s (the U/R feed-forward
    this law replaced left a boat started inside its circle swinging by 17% after 60 s)."""
    boat, radius = _circler(offset_m, yaw)
    track = _simulate([boat], 45.0, period=period, delay=delay)[:, 0]
    error = np.abs(np.hypot(*track.T) / radius - 1)
    assert error[round(25 / DT) :].max() < 0.05, error[round(25 / DT) :].max()
    assert error[-round(10 / DT) :].max() < 0.01, error[-round(10 / DT) :].max()


def test_waypoint_follower_passes_every_point_and_returns() -> None:
    path = ((60.0, 0.0), (60.0, 60.0), (120.0, 60.0))
    boat = Boat("b", "monohull", Pose(), "waypoints", 5.0, path=path, tolerance_m=5.0)
    track = _simulate([boat], 110.0)[:, 0]
    times: list[int] = []
    for point in (*path, path[1], path[0]):  # out, then back along the same path
        d = np.hypot(*(track - point).T)
        start = times[-1] + 50 if times else 0  # the next visit, after the previous one
        hit = np.flatnonzero(d[start:] < 5.0)
        assert hit.size, f"never within 5 m of {point} after step {start}"
        times.append(start + int(hit[0]))
    assert times == sorted(times)


def test_hold_position_brings_a_drifted_boat_back() -> None:
    boat = Boat("b", "monohull", Pose(x_m=15.0, y_m=-10.0, yaw_rad=2.0), "hold", 2.0, (0.0, 0.0))
    track = _simulate([boat], 60.0)[:, 0]
    assert np.hypot(*track[-1]) < 2.0
    assert np.hypot(*track[-250:].T).max() < 3.0


def _scenario(count: int, **traffic: object) -> dict[str, object]:
    mix = {"circle": 0.4, "waypoints": 0.3, "hold": 0.3}
    return {
        "seed": 7,
        "vessels": [{"id": "ego", "pose": {"x_m": 0.0, "y_m": 0.0}}],
        "traffic": {"count": count, "behaviour_mix": mix, **traffic},
    }


def test_same_seed_same_plan_and_another_seed_another() -> None:
    a = World.resolve(parse_scenario(_scenario(60))).traffic
    b = World.resolve(parse_scenario(_scenario(60))).traffic
    c = World.resolve(parse_scenario(_scenario(60, seed=8))).traffic
    assert a == b and a != c
    assert [x.id for x in a.boats[:3]] == ["boat_000", "boat_001", "boat_002"]
    assert len(a.buoys) == 5 * sum(x.behaviour == "waypoints" for x in a.boats)


def test_no_boat_overlaps_another_or_the_ego() -> None:
    plan = World.resolve(parse_scenario(_scenario(200, region={"size_m": [300.0, 300.0]}))).traffic
    xy = np.array([(0.0, 0.0)] + [(b.pose.x_m, b.pose.y_m) for b in plan.boats])
    r = footprint_m(load_vessel_model("monohull"))
    d = np.hypot(*(xy[:, None] - xy[None]).transpose(2, 0, 1)) + np.eye(len(xy)) * 1e9
    assert d.min() > 2 * r


def test_no_boat_starts_or_steers_on_land() -> None:
    """Synthetic terrain: land on the west half, a deep bay on the east half."""
    x = (np.arange(200) + 0.5) * 5.0
    grid = np.where(x[None, :] < 500.0, 10.0, -20.0) * np.ones((200, 1))
    terrain = Terrain(grid, 5.0)
    data = _scenario(80, region={"center_m": [500.0, 500.0], "size_m": [1000.0, 1000.0]})
    data["vessels"] = [{"id": "ego", "pose": {"x_m": 800.0, "y_m": 500.0}}]
    scenario = parse_scenario(data)
    plan = Planner(scenario, terrain, models=scenario_models(scenario)).plan()
    for b in plan.boats:
        assert terrain.depth(b.pose.x_m, b.pose.y_m) > 1.0, b
        if b.behaviour == "circle":
            assert b.center[0] - b.radius_m > 500.0, b
        for px, _ in b.path:
            assert px > 500.0, b


def test_a_bad_mix_is_refused_naming_the_field() -> None:
    from catabot.config.base import ScenarioError

    with pytest.raises(ScenarioError, match=r"traffic\.behaviour_mix"):
        parse_scenario(_scenario(3) | {"traffic": {"count": 3, "behaviour_mix": {"zigzag": 1}}})


def test_path_points_advance_for_many_boats_at_once() -> None:
    """Looping, back and forth, a one-point path, and a longer path adopted at run time."""
    boats = [Boat(f"b{i}", "monohull", Pose(), "waypoints", 5.0, path=((0.0, 0.0), (50.0, 0.0),
             (50.0, 50.0)), loop=i == 0, tolerance_m=5.0) for i in range(2)]  # fmt: skip
    boats.append(Boat("b2", "monohull", Pose(), "waypoints", 5.0, path=((9.0, 9.0),)))
    behaviours = Behaviours(boats)
    seen = []
    for _ in range(5):  # every boat sits on its current point: each call advances it
        pos = behaviours.paths[np.arange(3), behaviours.index]
        behaviours.command(pos, np.zeros(3), np.zeros((3, 2)))
        seen.append(behaviours.index.tolist())
    assert [s[0] for s in seen] == [1, 2, 0, 1, 2]  # loop
    assert [s[1] for s in seen] == [1, 2, 1, 0, 1]  # back and forth
    assert [s[2] for s in seen] == [0] * 5  # a single point stays the target
    behaviours.set_path(2, np.array([(0.0, 0.0), (1.0, 1.0), (2.0, 2.0), (3.0, 3.0)]), 2.0,
                        loop=False, tol=1.0)  # fmt: skip
    assert behaviours.paths.shape[1] == 4 and behaviours.length.tolist() == [3, 3, 4]
    assert behaviours.paths[0, :3].tolist() == [[0, 0], [50, 0], [50, 50]]


def test_a_release_resumes_the_boats_own_path_where_it_left_it() -> None:
    """A release sent a waypoint boat back to its first point, passed long before; one only
    held by a twist (the traffic never replaced its path) goes on as it was."""
    path = ((0.0, 0.0), (50.0, 0.0), (50.0, 50.0))
    behaviours = Behaviours([Boat("b", "monohull", Pose(), "waypoints", 5.0, path=path)])
    for _ in range(2):  # at each point in turn: now steering for the third
        behaviours.command(behaviours.paths[[0], behaviours.index], np.zeros(1), np.zeros((1, 2)))
    assert behaviours.index.tolist() == [2]
    behaviours.release(0)  # held by a twist only: nothing of its own was replaced
    assert behaviours.index.tolist() == [2]
    behaviours.set_path(0, np.array([(9.0, 9.0), (8.0, 8.0)]), 2.0, loop=True, tol=1.0)
    assert behaviours.index.tolist() == [0] and behaviours.speed.tolist() == [2.0]
    behaviours.release(0)
    assert behaviours.index.tolist() == [2] and behaviours.speed.tolist() == [5.0]
    assert behaviours.paths[0, :3].tolist() == [list(p) for p in path]


def test_a_release_after_a_behaviour_change_restores_the_boats_own_circle_and_hold() -> None:
    """`catabot set traffic.<boat>.behaviour` moved the centre; a release kept it, and a
    circling boat came back circling its hold point (an audit's run: 5.6-35.2 m off)."""
    circle = Boat("c", "monohull", Pose(yaw_rad=0.0), "circle", 5.0, (0.0, 19.1), 19.1, 1)
    hold = Boat("h", "monohull", Pose(x_m=100.0, yaw_rad=0.3), "hold", 2.0, (100.0, 0.0))
    behaviours = Behaviours([circle, hold])
    cfg = TrafficConfig()
    behaviours.set_behaviour(0, "hold", np.array([40.0, 40.0]), 1.0, cfg)
    behaviours.set_behaviour(1, "circle", np.array([100.0, 0.0]), 0.0, cfg)
    behaviours.release(0)
    behaviours.release(1)
    assert behaviours.centre.tolist() == [[0.0, 19.1], [100.0, 0.0]]
    assert behaviours.radius[0] == 19.1 and behaviours.hold_yaw.tolist() == [0.0, 0.3]
