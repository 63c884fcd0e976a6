"""Episodes drawn from their seed: the same seed the same scenario; starts and goals in
open water, clear of bodies; the env in the controller seat, the recording small."""

from __future__ import annotations

import math

import pytest

from catabot.gym.episode import Draw
from catabot.gym.options import EnvOptionsError, env_options
from catabot.world.placement import footprint_m, keel_depth_m


def test_the_same_seed_draws_the_same_episode_and_another_seed_another() -> None:
    draw = Draw(env_options(scenario="navigate", sensors=["lidar", "gps"]))
    a, b, c = (draw.episode(seed, "w") for seed in (3, 3, 4))
    assert a.scenario.model_dump_json() == b.scenario.model_dump_json()
    assert (a.start, a.goal) == (b.start, b.goal)
    assert (a.start, a.goal) != (c.start, c.goal)
    assert a.scenario.seed == 3 and a.scenario.name == "w"


def test_starts_and_goals_are_in_open_water_at_the_asked_distance() -> None:
    draw = Draw(env_options(scenario="navigate", start_radius_m=60, goal_distance_m=(20, 60)))
    assert draw.terrain is not None
    draft, radius = keel_depth_m(draw.model), footprint_m(draw.model)
    for seed in range(40):
        ep = draw.episode(seed, "w")
        for x, y in ((ep.start.x_m, ep.start.y_m), (ep.goal.x_m, ep.goal.y_m)):
            draw.terrain.check_start(x, y, draft_m=draft, footprint_m=radius)  # raises if not
            for buoy in ep.scenario.buoys:
                assert math.hypot(buoy.x_m - x, buoy.y_m - y) > radius
        assert math.hypot(ep.start.x_m - 300, ep.start.y_m - 320) <= 60
        assert 20 <= math.hypot(ep.goal.x_m - ep.start.x_m, ep.goal.y_m - ep.start.y_m) <= 60


def test_the_episode_scenario_seats_the_env_and_keeps_the_run_small() -> None:
    draw = Draw(env_options(scenario="navigate", sensors=["lidar"], action="twist",
                            control_hz=20, max_steps=100))  # fmt: skip
    s = draw.episode(1, "w").scenario
    (ego,) = s.vessels
    assert ego.script == []
    assert ego.controller is not None and ego.controller.participant == "gym"
    assert (ego.controller.rate_hz, ego.controller.command) == (20, "twist")
    assert [x.type for x in ego.sensors] == ["lidar"]  # the scenario's gps and imu left out
    assert ego.sensors[0].rate_hz == 20 and ego.sensors[0].params["columns"] == 256
    assert not s.recording.mcap and not s.recording.csv
    assert s.duration_s == pytest.approx(103 / 20)
    station = Draw(env_options(scenario="navigate", task="station_keep")).episode(1, "w")
    assert (station.goal.x_m, station.goal.y_m, station.goal.yaw_rad) == (
        station.start.x_m, station.start.y_m, station.start.yaw_rad,
    )  # fmt: skip


def test_the_scenarios_own_sensor_is_used() -> None:
    draw = Draw(env_options(scenario="navigate", sensors=["imu", "gps"]))
    (ego,) = draw.episode(0, "w").scenario.vessels
    assert [(x.name, x.rate_hz) for x in ego.sensors] == [("imu", 10.0), ("gps", 10.0)]


def test_bad_options_name_the_field() -> None:
    with pytest.raises(EnvOptionsError, match="sensors"):
        env_options(sensors=["sonar"])
    with pytest.raises(EnvOptionsError, match="control_hz"):
        env_options(control_hz=-1)
    with pytest.raises(EnvOptionsError, match="speed"):
        env_options(speed=3)
    with pytest.raises(EnvOptionsError, match=r"^control_hz: period 333333333 ns is not a whole"):
        Draw(env_options(control_hz=3))  # named as the keyword, not the scenario's field
    with pytest.raises(EnvOptionsError, match=r"reaches past the terrain \(600 x 600 m\): narrow"):
        Draw(env_options(start_radius_m=1e9)).episode(0, "w")  # "widen it" was the advice
    with pytest.raises(EnvOptionsError, match="vessel 'boat' is not in the scenario"):
        Draw(env_options(scenario="navigate", vessel="boat"))
    crowded = {"vessels": [{"id": "ego"}], "buoys": [{"id": "b", "x_m": 0.0, "y_m": 0.0}]}
    with pytest.raises(EnvOptionsError, match="no start in open water"):
        Draw(env_options(scenario=crowded, start_radius_m=0.0)).episode(0, "w")


def test_another_vessel_with_a_controller_no_program_starts_is_refused_before_any_run() -> None:
    """A swarm researcher's reset waited out the start timeout for its followers' stacks."""
    follower = {"id": "f1", "pose": {"x_m": 20.0, "y_m": 0.0},
                "controller": {"participant": "ctl_f1", "rate_hz": 10.0}}  # fmt: skip
    swarm = {"vessels": [{"id": "leader"}, follower]}
    with pytest.raises(
        EnvOptionsError,
        match=r"vessels.1 \(f1\) is driven by participant "
        r"'ctl_f1', which no program starts: an env drives one vessel \(leader\)",
    ):
        Draw(env_options(scenario=swarm))  # fmt: skip
    scripted = {"vessels": [{"id": "leader"}, {"id": "f1", "pose": {"x_m": 20.0, "y_m": 0.0}}]}
    assert Draw(env_options(scenario=scripted)).vessel == "leader"  # scripted: as they are


def test_a_dict_scenario_may_name_the_bundled_bay_bare() -> None:
    """A file could say `"bay.png"`; a dict given to the env got "file not found"."""
    data = {"terrain": {"elevation_image": "bay.png"}, "vessels": [{"id": "ego"}]}
    draw = Draw(env_options(scenario=data))
    assert draw.terrain is not None and draw.terrain.size_m == (600.0, 600.0)  # bay.json's
