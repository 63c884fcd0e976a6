"""Boats meeting boats (services/traffic/colregs.py): who gives way in each encounter of the
rules of the road, then two boats in a real PhysicsWorld meeting head-on and crossing."""

from __future__ import annotations

import math

import numpy as np

from catabot.config.scenario import Pose
from catabot.config.vessel import load_vessel_model
from catabot.world import rotations
from catabot.world.hulls import box_gaps, footprints
from catabot.world.placement import footprint_m
from catabot.world.traffic_plan import Boat
from services.physics.control import TwistControllerBank
from services.physics.world import PhysicsWorld
from services.traffic.avoid import KeepClear, Obstacles
from services.traffic.behaviours import Behaviours
from services.traffic.colregs import OFFSETS, SPEEDS, choose
from services.traffic.predict import Movers

WIDTH, RADIUS = 4.5, 2.5  # a boat's footprint plus the clearance, the other's footprint


def picks(
    boats: list[tuple[float, float, float, float]], turn: tuple[float, ...] = ()
) -> list[tuple[float, float]]:
    """Each boat's (course change in degrees, part of its speed) for boats (x, y, course
    in degrees, speed) meeting each other, each turning at its rate in `turn` (rad/s, to
    port; none: straight on)."""
    xy = np.array([(x, y) for x, y, _, _ in boats], dtype=float)
    chi = np.radians([c for _, _, c, _ in boats])
    speed = np.array([v for _, _, _, v in boats], dtype=float)
    vel = speed[:, None] * np.column_stack((np.cos(chi), np.sin(chi)))
    n = len(boats)
    rates = np.array(turn or [0.0] * n)
    own, seen = (Movers(xy, vel, chi, rates, np.full(n, size)) for size in (WIDTH, RADIUS))
    boat, other = (a.ravel() for a in np.meshgrid(np.arange(n), np.arange(n), indexing="ij"))
    pairs = (boat[boat != other], other[boat != other])
    pick = choose(own, seen, pairs, horizon_s=8.0, last=np.zeros(n, dtype=np.intp))
    return [(round(math.degrees(OFFSETS[k])), float(SPEEDS[k])) for k in pick]


KEEPS_ON = (0, 1.0)


def test_head_on_both_turn_to_starboard() -> None:
    a, b = picks([(0.0, 0.0, 0.0, 5.0), (60.0, 0.5, 180.0, 5.0)])
    assert a != KEEPS_ON and b != KEEPS_ON
    assert a[0] <= 0 and b[0] <= 0  # to starboard (or slowing on course), never to port


def test_crossing_the_boat_with_the_other_on_its_starboard_side_gives_way_first() -> None:
    give, stand = picks([(0.0, 0.0, 0.0, 5.0), (38.0, -38.0, 90.0, 5.0)])  # CPA in 7.6 s
    assert give == (-15, 1.0)  # early and to starboard, to pass astern (rules 15, 16)
    assert stand == KEEPS_ON  # holds its course and speed (rule 17(a))
    give, _ = picks([(0.0, 0.0, 0.0, 5.0), (30.0, -30.0, 90.0, 5.0)])  # closer: both act
    assert give != KEEPS_ON and give[0] <= 0  # the giver still never turns to port


def test_the_overtaking_boat_keeps_out_of_the_way() -> None:
    overtaking, _ = picks([(0.0, 0.0, 0.0, 5.0), (20.0, 0.5, 0.0, 2.0)])
    assert overtaking != KEEPS_ON and overtaking[0] <= 0
    assert picks([(0.0, 0.0, 0.0, 5.0), (24.0, 0.5, 0.0, 2.0)]) == [KEEPS_ON] * 2  # not yet


def test_a_stand_on_boat_acts_when_the_other_leaves_it_too_late() -> None:
    give, stand = picks([(0.0, 0.0, 0.0, 5.0), (7.0, -7.0, 90.0, 5.0)])  # CPA in 1.4 s
    assert stand != KEEPS_ON and stand[0] <= 0  # rule 17(b), and to starboard (17(c))
    assert give != KEEPS_ON


def test_a_boat_adrift_ahead_is_given_way_to() -> None:
    mover, adrift = picks([(0.0, 0.0, 0.0, 5.0), (30.0, 0.0, 90.0, 0.0)])
    assert mover != KEEPS_ON and adrift == KEEPS_ON


def test_a_boat_whose_circle_runs_into_another_sees_it_coming() -> None:
    circling = (0.0, 0.0, 0.0, 5.0)  # turning to port at 0.4 rad/s: a circle 25 m across
    moored = (0.0, 25.0, 0.0, 0.0)  # at the top of that circle, 7.9 s away
    assert picks([circling, moored], turn=(0.4, 0.0))[0] != KEEPS_ON
    assert picks([circling, moored])[0] == KEEPS_ON  # straight on, it would pass 25 m off


def test_boats_that_pass_clear_keep_their_own_law() -> None:
    assert picks([(0.0, 0.0, 0.0, 5.0), (60.0, 30.0, 180.0, 5.0)]) == [KEEPS_ON] * 2  # wide
    assert picks([(0.0, 0.0, 0.0, 5.0), (-30.0, 0.0, 180.0, 5.0)]) == [KEEPS_ON] * 2  # opening
    assert picks([(0.0, 0.0, 0.0, 5.0), (200.0, 0.0, 180.0, 5.0)]) == [KEEPS_ON] * 2  # far
    assert picks([(0.0, 0.0, 0.0, 5.0)]) == [KEEPS_ON]  # alone


DT = 0.01


def _meeting(starts: list[tuple[float, float, float]], *, rules: bool, speed: float = 5.0) -> float:
    """Monohulls (the default traffic boat) from `starts` (x, y, yaw in degrees), each on a
    straight path of 200 m at `speed` m/s, keeping clear of each other or not; the least gap
    (m) between their hull boxes seen from above over 45 s (< 0: they touched)."""
    model = load_vessel_model("monohull")
    boats, bodies = [], []
    for i, (x, y, degrees) in enumerate(starts):
        heading = math.radians(degrees)
        far = (x + 200.0 * math.cos(heading), y + 200.0 * math.sin(heading))
        pose = Pose(x_m=x, y_m=y, yaw_rad=heading)
        boats.append(Boat(f"b{i}", "monohull", pose, "waypoints", speed, path=((x, y), far)))
        bodies.append((f"b{i}", model, (x, y, 0.0, heading)))
    n, r = len(starts), footprint_m(model)
    world = PhysicsWorld(bodies, dt_s=DT)
    clear = KeepClear(np.zeros((0, 2)), np.zeros(n), np.full(n, r + 2.0), 8.0)
    guide, bank = Behaviours(boats, clear=clear), TwistControllerBank([model] * n, dt_s=DT)
    offset, half = footprints([model] * n)
    rows, set_point, least = np.arange(n), np.zeros((n, 2)), math.inf
    under_way = np.ones(n, dtype=bool)
    for k in range(round(45.0 / DT)):
        s = world.state_arrays()
        yaw = rotations.yaw_of_quaternions(s.orientation)
        if k % 10 == 0:
            over_ground = rotations.turn_xy(s.linear_velocity[:, :2], yaw)
            turn = s.angular_velocity[:, 2]
            seen = Obstacles(s.position[:, :2], np.full(n, r), rows, over_ground, turn, under_way)
            surge, rate = guide.command(s.position[:, :2], yaw, s.linear_velocity,
                                        seen if rules else None)  # fmt: skip
            set_point = np.stack([surge, rate], axis=1)
        measured = np.stack([s.linear_velocity[:, 0], s.angular_velocity[:, 2]], axis=1)
        world.set_thrusts(rows, bank.command(rows, set_point, measured))
        world.step()
        centre = s.position[:, :2] + rotations.turn_xy(offset, yaw)
        gap = box_gaps(centre, yaw, half, np.array([0]), np.array([1]))
        least = min(least, float(gap[0]))
    return least


HEAD_ON = [(0.0, 0.0, 0.0), (120.0, 1.0, 180.0)]
CROSSING = [(0.0, 0.0, 0.0), (70.0, -70.0, 90.0)]


def test_two_boats_head_on_pass_each_other_clear() -> None:
    assert _meeting(HEAD_ON, rules=True) > 1.0
    assert _meeting(HEAD_ON, rules=False) < 0.0  # the same boats without the rules collide


def test_slow_boats_head_on_turn_and_pass_clear() -> None:
    """At 2.5 m/s both only slowed (a turn's candidates went at the speed a slowed boat had
    left, and stopping put the hazard past the horizon) and met bow to bow."""
    assert _meeting([(0.0, 0.0, 0.0), (120.0, 0.0, 180.0)], rules=True, speed=2.5) > 1.0


def test_two_boats_crossing_pass_each_other_clear() -> None:
    assert _meeting(CROSSING, rules=True) > 1.0
    assert _meeting(CROSSING, rules=False) < 0.0
