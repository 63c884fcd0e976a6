"""Reward and termination from the observed states: collisions by hull boxes (rotated
ones too), grounding on the elevation grid under the hull, progress to the goal."""

from __future__ import annotations

import math

import numpy as np
import pytest

from catabot.bus.messages import BodyStates
from catabot.config.load import parse_scenario
from catabot.gym.episode import Goal
from catabot.gym.judge import Judge
from catabot.gym.options import env_options
from catabot.world.terrain import Terrain
from catabot.world.world import World


def world(*, terrain: Terrain | None = None) -> World:
    scenario = parse_scenario(
        {
            "vessels": [
                {"id": "ego", "pose": {"x_m": 50.0, "y_m": 50.0}},
                {"id": "other", "model": "wamv", "pose": {"x_m": 80.0, "y_m": 50.0}},
            ],
            "buoys": [{"id": "b1", "x_m": 50.0, "y_m": 70.0}],
        }
    )
    w = World.resolve(scenario)
    if terrain is not None:
        object.__setattr__(w, "terrain", terrain)
    return w


def states(w: World, poses: dict[str, tuple[float, float, float]], z: float = 0.0) -> BodyStates:
    start = w.start_states()
    pos, quat = start.position.copy(), start.orientation.copy()
    for body, (x, y, yaw) in poses.items():
        row = w.body(body).row
        pos[row] = (x, y, z if body == "ego" else 0.0)
        quat[row] = (0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2))
    zero = np.zeros_like(pos)
    return BodyStates(0, 0, start.ids, pos, quat, zero, zero, zero, zero)


def test_boxes_touching_collide_and_apart_do_not() -> None:
    w = world()
    judge = Judge(w, "ego", env_options())
    _, hi = w.body("ego").model.hull_box()
    olo, _ = w.body("other").model.hull_box()
    touching = hi[0] - olo[0] - 0.05  # the other's stern 5 cm into the ego's bow
    assert judge.collision(states(w, {"other": (50.0 + touching, 50.0, 0.0)})) == "other"
    apart = hi[0] - olo[0] + 0.05
    assert judge.collision(states(w, {"other": (50.0 + apart, 50.0, 0.0)})) is None
    assert judge.collision(states(w, {})) is None  # the starts are apart


def test_rotated_boxes_collide_by_their_corners_only() -> None:
    """A box turned 45 degrees beside the ego: inside the circle around its hull, clear of the
    hull itself, until its corner crosses the ego's side."""
    w = world()
    judge = Judge(w, "ego", env_options())
    _, hi = w.body("ego").model.hull_box()
    olo, ohi = w.body("other").model.hull_box()
    corner = math.hypot(*(ohi[:2] - olo[:2])) / 2  # centre to corner (centred box)
    y_clear = hi[1] + corner + 0.05
    diagonal = math.atan2(ohi[1] - olo[1], ohi[0] - olo[0])
    tilt = math.pi / 2 - diagonal  # the corner points straight at the ego's side
    assert judge.collision(states(w, {"other": (50.0, 50.0 + y_clear, tilt)})) is None
    assert judge.collision(states(w, {"other": (50.0, 50.0 + y_clear - 0.1, tilt)})) == "other"


def test_a_buoy_hit_is_named() -> None:
    w = world()
    judge = Judge(w, "ego", env_options())
    assert judge.collision(states(w, {"ego": (50.0, 69.5, math.pi / 2)})) == "b1"


def test_grounding_when_the_hull_bottom_reaches_the_ground() -> None:
    """A slope rising to the east: the hull grounds where the ground under its bottom rises
    above the keel, not before."""
    xs = np.arange(100) + 0.5
    ground = np.tile(np.clip(-5.0 + 0.1 * (xs - 50.0), -5.0, 3.0), (100, 1))
    w = world(terrain=Terrain(ground, 1.0))
    judge = Judge(w, "ego", env_options())
    lo, hi = w.body("ego").model.hull_box()
    keel = lo[2]  # body z of the hull bottom
    # ground at x is -5 + 0.1 (x - 50); the bow (x + hi[0]) touches where that equals keel
    touch_x = 50.0 + (keel + 5.0) / 0.1 - hi[0]
    assert not judge.grounded(states(w, {"ego": (touch_x - 0.5, 50.0, 0.0)}))
    assert judge.grounded(states(w, {"ego": (touch_x + 0.5, 50.0, 0.0)}))
    # the same place, the hull lifted by a wave crest: afloat
    assert not judge.grounded(states(w, {"ego": (touch_x + 0.5, 50.0, 0.0)}, z=0.2))


def test_reward_is_progress_less_energy_and_ends_on_events() -> None:
    w = world()
    judge = Judge(w, "ego", env_options(goal_radius_m=2.0))
    judge.start(Goal(60.0, 50.0, 0.0), states(w, {}))
    verdict = judge(states(w, {"ego": (52.0, 50.0, 0.0)}), np.array([0.5, 0.5]))
    assert verdict.reward == pytest.approx(2.0 - 0.01 * 0.25)
    assert not verdict.terminated and verdict.distance_m == pytest.approx(8.0)
    reached = judge(states(w, {"ego": (58.5, 50.0, 0.0)}), np.zeros(2))
    assert reached.terminated and reached.reached
    assert reached.reward == pytest.approx(6.5 + 100.0)
    hit = judge(states(w, {"ego": (50.0, 69.5, math.pi / 2)}), np.zeros(2))
    assert hit.terminated and hit.collision == "b1" and hit.reward < -90


def test_flags_give_reset_the_outcome_keys_of_step() -> None:
    w = world()
    judge = Judge(w, "ego", env_options(goal_radius_m=3.0))
    judge.start(Goal(52.0, 50.0, 0.0), states(w, {}))
    clear = judge.flags(states(w, {}))
    assert clear == {"reached": True, "collision": None, "grounded": False}  # 2 m from it
    _, hi = w.body("ego").model.hull_box()
    olo, _ = w.body("other").model.hull_box()
    touching = states(w, {"other": (50.0 + hi[0] - olo[0] - 0.05, 50.0, 0.0)})
    assert judge.flags(touching)["collision"] == "other"
