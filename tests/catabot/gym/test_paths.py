"""The other vessels' predicted paths, which episode starts keep clear of (catabot/gym/paths.py)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from catabot.config.load import parse_scenario
from catabot.config.scenario import Scenario
from catabot.gym.episode import Draw
from catabot.gym.options import env_options
from catabot.gym.paths import PATH_MARGIN_M, SAMPLE_S, path_points
from catabot.world.placement import footprint_m, scenario_models


def _world(script: list[dict[str, object]], current: tuple[float, float] = (0.0, 0.0)) -> Scenario:
    boat = {"id": "b", "pose": {"x_m": 10.0, "y_m": 0.0, "yaw_rad": 0.0}, "script": script}
    return parse_scenario(
        {"vessels": [{"id": "ego"}, boat], "water": {"current": {"velocity_mps": list(current)}}}
    )


def _path(world: Scenario, seconds: float) -> np.ndarray:
    """The points alone."""
    return path_points(world.vessels[1], world, seconds=seconds)[:, :2]


def test_a_twist_step_is_an_arc_and_a_rest_before_it_stays_put() -> None:
    circle = _world([{"t_s": 2.0, "twist": {"surge_mps": 1.0, "yaw_rate_radps": 0.05}}])
    path = _path(circle, 2.0 + 20 * math.pi)  # half a lap after a 2 s rest
    assert path.shape == (int((2.0 + 20 * math.pi) / SAMPLE_S) + 1, 2)
    assert np.allclose(path[: int(2 / SAMPLE_S) + 1], (10.0, 0.0))
    assert np.allclose(np.hypot(path[:, 0] - 10.0, path[:, 1] - 20.0), 20.0)  # radius u / r
    assert path[:, 1].max() == pytest.approx(40.0, abs=0.01)  # across the circle


def test_a_straight_run_is_carried_by_the_current() -> None:
    run = _world([{"t_s": 0.0, "twist": {"surge_mps": 2.0, "yaw_rate_radps": 0.0}}], (0.0, 0.5))
    assert np.allclose(_path(run, 10.0)[-1], (30.0, 5.0))


def test_a_path_ends_at_its_first_thrust_step_and_no_script_rests() -> None:
    steps = [
        {"t_s": 0.0, "twist": {"surge_mps": 1.0, "yaw_rate_radps": 0.0}},
        {"t_s": 4.0, "thrust": [1.0, 1.0]},
    ]
    path = _path(_world(steps), 30.0)
    assert len(path) == int(4.0 / SAMPLE_S) + 1 and np.allclose(path[-1], (14.0, 0.0))
    assert np.allclose(_path(_world([]), 30.0), (10.0, 0.0))
    margins = path_points(_world([]).vessels[1], _world([]), seconds=100.0)[:, 2]
    assert (margins[0], margins[-1]) == pytest.approx((PATH_MARGIN_M, PATH_MARGIN_M + 6.0))


def test_station_keeping_starts_keep_clear_of_the_harbours_circling_wamv() -> None:
    """Its WAM-V circles 20 m around (299, 319), through the ego's home: an ego that held
    still was rammed after 41 s (seed 1)."""
    draw = Draw(env_options(scenario="harbour", task="station_keep"))
    wamv = next(v for v in draw.base.vessels if v.id == "wamv")
    path = path_points(wamv, draw.base, seconds=60.3)
    clear = footprint_m(scenario_models(draw.base)["wamv"]) + path[:, 2] + draw.radius
    for seed in range(40):
        ep = draw.episode(seed, "w")
        assert (np.hypot(path[:, 0] - ep.start.x_m, path[:, 1] - ep.start.y_m) > clear).all()
