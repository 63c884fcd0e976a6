"""Traffic boats keep clear (services/traffic/avoid.py): the rules one by one, then boats in
a real PhysicsWorld rounding their marks and steering round other buoys without touching."""

from __future__ import annotations

import numpy as np
import pytest
from pydantic import ValidationError

from catabot.config.scenario import Pose
from catabot.config.traffic import AvoidParams, TrafficConfig
from catabot.config.vessel import load_vessel_model
from catabot.world import rotations
from catabot.world.placement import footprint_m
from catabot.world.traffic_plan import Boat
from services.physics.control import TwistControllerBank
from services.physics.world import PhysicsWorld
from services.traffic.avoid import (
    MARGIN,
    KeepClear,
    Obstacles,
    _on_arc,
    corridor_turn,
    drifted,
    mark_aim,
    marks_on,
)
from services.traffic.behaviours import Behaviours

NO_MARKS = np.full((1, 1, 2), np.nan)


def turn_for(
    xy: tuple[float, float], *, own: int = -1, marks: np.ndarray = NO_MARKS, law: float = 0.0
) -> tuple[float, bool]:
    """One boat at the origin heading +x at 5 m/s (its law's turn `law`, 40 m ahead, 5 m
    wide, a full turn 0.35 rad/s), one obstacle: its turn and whether it backs off."""
    obstacles = Obstacles.fixed(np.array([xy], dtype=float), np.array([0.3]), np.array([own]))
    zero, one = np.zeros(1), np.ones(1)
    arcs = (law * one, 0.07 * one, 40.0 * one, 5.0 * one)
    turn, stop = corridor_turn(zeros2(), zero, *arcs, obstacles, marks)
    return float(turn[0]), bool(stop[0])


def zeros2() -> np.ndarray:
    return np.zeros((1, 2))


def test_an_obstacle_dead_ahead_takes_the_clear_turn_nearest_the_law_to_starboard() -> None:
    assert turn_for((20.0, 0.0)) == (-0.75, False)  # a tie: COLREGs, to starboard
    assert turn_for((20.0, 0.5)) == (-0.75, False)
    assert turn_for((20.0, -4.0)) == (0.5, False)  # well to starboard: round it to port
    _, off = _on_arc(np.array([20.0]), np.array([-4.0]), np.array([0.5 * 0.07]))
    assert abs(off[0]) >= MARGIN * 5.3  # the turn taken clears it by the margin


def test_a_boat_walled_in_takes_the_turn_that_passes_widest() -> None:
    assert turn_for((10.0, 1.75), law=0.5) == (-1.0, False)  # every arc meets it


def test_what_is_behind_beside_beyond_reach_or_its_own_is_no_threat() -> None:
    for xy in ((-20.0, 0.0), (20.0, 8.0), (60.0, 0.0)):  # astern, clear, beyond reach
        assert np.isnan(turn_for(xy)[0]) and not turn_for(xy)[1]
    assert np.isnan(turn_for((20.0, 0.0), own=0)[0])  # itself
    assert np.isnan(turn_for((20.0, 0.0), marks=np.array([[[20.2, 0.1]]]))[0])  # its mark


def test_one_alongside_or_under_the_bow_is_met_at_once() -> None:
    assert turn_for((0.5, 3.0)) == (-1.0, False)  # close on the port beam: away
    assert turn_for((0.5, -3.0)) == (1.0, False)
    assert turn_for((2.0, 0.3)) == (-1.0, True)  # under the bow: back off while turning


def test_the_corridor_follows_the_arc_the_law_turns_on() -> None:
    along, off = _on_arc(np.array([10.0]), np.array([10.0]), np.array([0.1]))
    np.testing.assert_allclose([along[0], off[0]], [5.0 * np.pi, 0.0], atol=1e-9)  # on it
    law = 0.1 / 0.07  # the law's arc through (10, 10), a full turn's curvature 0.07
    assert not np.isnan(turn_for((10.0, 10.0), law=law)[0])  # met on the arc
    assert np.isnan(turn_for((10.0, 10.0))[0])  # not on the line


def test_a_mark_whose_buoy_drifted_off_its_anchor_is_still_a_mark() -> None:
    """A soft mooring lets a buoy ride 3 m off its anchor in a 0.5 m/s current: it was then
    taken for an obstacle on the boat's own way, while the boat aimed beside its anchor."""
    anchor, buoy = np.array([[20.0, 0.0]]), np.array([[20.0, 3.0]])
    drifting = Obstacles(buoy, np.array([0.3]), np.array([-1]), np.zeros((1, 2)), np.zeros(1),
                         np.zeros(1, dtype=bool), home=anchor)  # fmt: skip
    zero, one = np.zeros(1), np.ones(1)
    arcs = (zero, 0.07 * one, 40.0 * one, 5.0 * one)
    turn, _ = corridor_turn(zeros2(), zero, *arcs, drifting, anchor[None])  # its own mark
    assert np.isnan(turn[0])
    turn, _ = corridor_turn(zeros2(), zero, *arcs, drifting, NO_MARKS)  # a stranger's buoy
    assert not np.isnan(turn[0])
    np.testing.assert_array_equal(drifted(np.array([[20.2, 0.1], [50.0, 0.0]]), drifting),
                                  [[20.0, 3.0], [50.0, 0.0]])  # fmt: skip


def test_marks_are_aimed_at_to_their_right() -> None:
    path = np.array([[0.0, 0.0], [100.0, 0.0], [100.0, 50.0]])
    np.testing.assert_array_equal(marks_on(path, np.array([[100.2, 0.1]])), [False, True, False])
    aim = mark_aim(np.array([[0.0, 0.0]]), np.array([[100.0, 0.0]]), np.array([6.0]))
    np.testing.assert_allclose(aim, [[100.0, -6.0]])  # the mark left to port


def test_bad_settings_are_refused_by_name() -> None:
    for bad in ({"lookahead_s": 0}, {"clearance_m": -1}, {"buoys": "yes"}):
        with pytest.raises(ValidationError, match=next(iter(bad))):
            TrafficConfig(avoid=AvoidParams(**bad))  # type: ignore[arg-type]


DT = 0.01
Point = tuple[float, float]
Buoys = list[tuple[str, Point]]
PATH = [(120.0, 0.0), (120.0, 80.0)]  # marks, each with a buoy; a stranger's buoy on leg 1
BUOYS = [("m0", PATH[0]), ("m1", PATH[1]), ("stranger", (60.0, 0.4))]


def _voyage(
    *, avoid: bool, seconds: float = 70.0, path: list[Point] = PATH, buoys: Buoys = BUOYS,
    yaw: float = 0.0,
) -> tuple[float, np.ndarray, int]:  # fmt: skip
    """A monohull from the origin along `path` past moored buoys; returns its least gap to
    any buoy (hull footprint to buoy footprint), how far the buoys moved, and the
    waypoints it reached."""
    pose = Pose(x_m=0.0, y_m=0.0, yaw_rad=yaw)
    boat = Boat("b", "monohull", pose, "waypoints", 5.0, path=tuple(path))
    model, buoy = load_vessel_model("monohull"), load_vessel_model("buoy")
    world = PhysicsWorld([("b", model, (0.0, 0.0, 0.0, yaw))], dt_s=DT, buoys=buoys)
    own_r, buoy_r = footprint_m(model), footprint_m(buoy)
    anchors = np.array([xy for _, xy in buoys])
    pass_m = np.array([own_r + buoy_r + 2.0 if avoid else 0.0])
    clear = KeepClear(anchors if avoid else anchors[:0], pass_m, np.array([own_r + 2.0]), 8.0)
    guide, bank = Behaviours([boat], clear=clear), TwistControllerBank([model], dt_s=DT)
    gaps, reached, set_point = [], 0, np.zeros((1, 2))
    for k in range(round(seconds / DT)):
        s, b = world.state_arrays(), world.buoy_state_arrays()
        if k % 10 == 0:
            yaw = rotations.yaw_of_quaternions(s.orientation)
            seen = Obstacles.fixed(b.position[:, :2], np.full(len(buoys), buoy_r), np.array([-1]))
            surge, rate = guide.command(s.position[:, :2], yaw, s.linear_velocity,
                                        seen if avoid else None)  # fmt: skip
            set_point = np.stack([surge, rate], axis=1)
            reached = max(reached, int(guide.index[0]) + (guide.step[0] < 0) * 2)
        measured = np.stack([s.linear_velocity[:, 0], s.angular_velocity[:, 2]], axis=1)
        world.set_thrusts(np.array([0]), bank.command(np.array([0]), set_point, measured))
        world.step()
        gaps.append(np.hypot(*(b.position[:, :2] - s.position[0, :2]).T).min())
    moved = np.hypot(*(world.buoy_state_arrays().position[:, :2] - anchors).T)
    return float(min(gaps)) - own_r - buoy_r, moved, reached


def test_a_boat_rounds_its_marks_and_steers_round_a_stranger_without_touching() -> None:
    gap, moved, reached = _voyage(avoid=True)
    assert gap > 0.0  # the footprint circles never overlapped (the clearance is 2 m)
    assert moved.max() < 1e-3  # no buoy was pushed
    assert reached >= 2  # and it still sailed its path: both marks, then turned back


def test_without_it_the_same_boat_rams_the_buoys() -> None:
    gap, moved, _ = _voyage(avoid=False)
    assert gap < 0.0 and moved.max() > 0.05


def test_a_boat_keeps_clear_of_its_own_later_marks() -> None:
    """Its third mark lies on its way to the first: all its marks had been left out of the
    corridor (it rounds them), so it passed its own buoy 1 m off, or rammed it and dragged
    it 6 m; only the mark it steers for now is its to round."""
    path = [(100.0, 0.0), (60.0, 60.0), (20.0, 0.0)]
    gap, moved, _ = _voyage(avoid=True, seconds=12.0, path=path,
                            buoys=[(f"m{i}", xy) for i, xy in enumerate(path)])  # fmt: skip
    assert gap > 0.0 and moved.max() < 1e-3


def test_a_boat_turning_for_its_waypoint_past_buoys_gets_there() -> None:
    """A trial's boat, heading away from its waypoint with two other boats' buoys beside
    its turn: the full turn away from a buoy on its arc, then back to its law, flipped its
    yaw rate between the limits at every guidance tick, and in 30 s it made 3.6 m."""
    buoys = [("x0", (12.6, 18.2)), ("x1", (22.7, 6.9))]
    gap, moved, reached = _voyage(avoid=True, seconds=35.0, path=[(60.0, 0.0), (60.0, -60.0)],
                                  buoys=buoys, yaw=2.8)  # fmt: skip
    assert reached >= 1 and gap > 0.0 and moved.max() < 1e-3
