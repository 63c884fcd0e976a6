"""The traffic plan keeps moored buoys clear of every start and of every circling track, and
keeps room between the boats' starts."""

from __future__ import annotations

import numpy as np
import pytest

from catabot.config.base import ScenarioError
from catabot.config.load import parse_scenario
from catabot.config.vessel import load_vessel_model
from catabot.world.placement import CLEARANCE_M, footprint_m
from catabot.world.traffic_plan import START_ROOM_M, TrafficPlan
from catabot.world.world import World
from tests.paths import BAY

HULL = footprint_m(load_vessel_model("monohull"))
BUOY = footprint_m(load_vessel_model("buoy"))


def _plan(count: int, **traffic: object) -> TrafficPlan:
    data = {
        "seed": 3,
        "vessels": [{"id": "ego", "pose": {"x_m": 0.0, "y_m": 0.0}}],
        "buoys": [{"id": "mark", "x_m": 40.0, "y_m": 0.0}],
        "traffic": {
            "count": count,
            "behaviour_mix": {"circle": 0.5, "waypoints": 0.5},
            "region": {"size_m": [400.0, 400.0]},
            "waypoints": {"region": {"size_m": [400.0, 400.0]}},
            **traffic,
        },
    }
    return World.resolve(parse_scenario(data)).traffic


def test_no_boat_starts_on_a_buoy_and_no_circle_runs_through_one() -> None:
    plan = _plan(120)
    buoys = np.array([(40.0, 0.0)] + [(b.x_m, b.y_m) for b in plan.buoys])
    assert len(buoys) > 150  # the region is crowded enough for the check to bite
    starts = np.array([(0.0, 0.0)] + [(b.pose.x_m, b.pose.y_m) for b in plan.boats])
    gap = np.hypot(*(starts[:, None] - buoys[None]).transpose(2, 0, 1))
    assert gap.min() > HULL + BUOY
    for boat in (b for b in plan.boats if b.behaviour == "circle"):
        off_ring = np.abs(np.hypot(*(buoys - boat.center).T) - boat.radius_m)
        assert off_ring.min() > HULL + BUOY, boat.id


def test_buoys_never_overlap_even_where_every_path_shares_its_points() -> None:
    points = [[60.0, 60.0], [-60.0, 60.0], [-60.0, -60.0]]
    plan = _plan(6, behaviour_mix={"waypoints": 1.0}, waypoints={"points": points})
    assert [(b.x_m, b.y_m) for b in plan.buoys] == [tuple(p) for p in points]
    assert all(b.path == tuple(map(tuple, points)) for b in plan.boats)


def test_boats_start_with_room_between_them_and_an_explicit_start_as_given() -> None:
    """Placed one footprint and half a metre apart, boats at rest touched within their first
    seconds of getting under way (4 of 6 touching pairs over three seeds of Table II's
    100-boat cell); a start the user gives is taken as given."""
    near = {"index": 1, "x_m": 100.0, "y_m": 2 * HULL + 1.0, "model": "monohull"}
    first = {"index": 0, "x_m": 100.0, "y_m": 0.0, "model": "monohull"}
    plan = _plan(120, models=[{"model": "monohull"}], boats=[first, near])
    starts = np.array([(b.pose.x_m, b.pose.y_m) for b in plan.boats])
    gap = np.hypot(*(starts[:, None] - starts[None]).transpose(2, 0, 1))
    np.fill_diagonal(gap, np.inf)
    gap[0, 1] = gap[1, 0] = np.inf  # the two the user placed
    assert gap.min() >= 2 * HULL + 10.0 + CLEARANCE_M == 2 * HULL + START_ROOM_M + CLEARANCE_M
    assert np.hypot(*(starts[0] - starts[1])) == 2 * HULL + 1.0


def test_a_given_waypoint_where_a_boat_starts_is_refused_naming_both() -> None:
    """Its buoy was laid under the boat: a traffic collision from tick 0 in every run."""
    here = {"index": 0, "x_m": 100.0, "y_m": 100.0, "behaviour": "waypoints"}
    points = [[100.0, 100.0], [150.0, 100.0]]
    with pytest.raises(ScenarioError) as info:
        _plan(1, boats=[here], waypoints={"points": points})
    assert str(info.value).endswith(
        "traffic: boat_000's waypoint (100, 100) is 0.00 m from where boat_000 starts: its buoy "
        "would start under that boat; move the point or the start, or traffic.waypoints.buoys: "
        "false"
    )
    _plan(1, boats=[here], waypoints={"points": points, "buoys": False})  # no buoy: no clash


def test_a_start_that_is_not_free_says_what_it_overlaps() -> None:
    on_mark = {"index": 0, "x_m": 40.0, "y_m": 0.5}
    with pytest.raises(ScenarioError, match=r"boat 0 at \(40.0, 0.5\): its footprint \(.* m "
                       r"about its origin\) overlaps a buoy \(scenario or waypoint\)"):  # fmt: skip
        _plan(1, boats=[on_mark])
    on_ego = {"index": 1, "x_m": 1.0, "y_m": 0.0}  # boat_000 is drawn far from the ego
    with pytest.raises(ScenarioError, match=r"boat 1 at \(1.0, 0.0\): its hull overlaps ego's "
                       r"by .* m \(seen from above\)"):  # fmt: skip
        _plan(2, boats=[on_ego])
    with pytest.raises(ScenarioError, match=r"no free open water for boat .* give a larger "
                       r"traffic.region .* or fewer boats \(traffic.count 40\)"):  # fmt: skip
        _plan(40, region={"size_m": [30.0, 30.0]})


def test_given_starts_may_lie_alongside_each_other_but_not_overlap() -> None:
    """A harbour's boats moored side by side (3 m apart, 1.3 m beams): a disc around each
    whole hull had refused them, where scenario vessels alongside each other are fine."""
    side = [{"index": 0, "x_m": 14.0, "y_m": 0.0, "yaw_rad": 0.0, "behaviour": "hold"},
            {"index": 1, "x_m": 14.0, "y_m": 3.0, "yaw_rad": 0.0, "behaviour": "hold"}]  # fmt: skip
    plan = _plan(2, boats=side)
    assert [(b.pose.x_m, b.pose.y_m) for b in plan.boats] == [(14.0, 0.0), (14.0, 3.0)]
    side[1]["y_m"] = 1.0
    with pytest.raises(ScenarioError, match=r"boat 1 at \(14.0, 1.0\): its hull overlaps "
                       r"boat_000's by 0\.\d\d m"):  # fmt: skip
        _plan(2, boats=side)
    side[1] |= {"y_m": 2.5, "yaw_rad": 1.5708}  # turned across the first: stern into its side
    with pytest.raises(ScenarioError, match="its hull overlaps boat_000's"):
        _plan(2, boats=side)


def test_drawn_buoys_keep_off_a_vessels_way_to_its_task() -> None:
    """The student's river run: a traffic buoy drawn onto the ego's route took its goal."""
    task = {
        "route": [[0.0, 0.0], [120.0, 0.0], [120.0, 80.0]],
        "goal": {"x_m": 0.0, "y_m": 80.0, "radius_m": 6.0},
    }
    data = {
        "seed": 3,
        "vessels": [{"id": "ego", "pose": {"x_m": -30.0, "y_m": 0.0}, "task": task}],
        "traffic": {"count": 40, "behaviour_mix": {"waypoints": 1.0},
                    "region": {"size_m": [400.0, 400.0]}, "waypoints": {"count": 5,
                    "region": {"center_m": [60.0, 40.0], "size_m": [200.0, 140.0]}}},
    }  # fmt: skip
    buoys = np.array([(b.x_m, b.y_m) for b in World.resolve(parse_scenario(data)).traffic.buoys])
    assert len(buoys) > 150  # the lane crosses the buoys' region: the rule has work to do
    way = np.array([[-30.0, 0.0], [0.0, 0.0], [120.0, 0.0], [120.0, 80.0], [0.0, 80.0]])
    a, b = way[:-1], way[1:]
    t = np.clip(np.einsum("kmi,mi->km", buoys[:, None] - a, b - a) / ((b - a) ** 2).sum(1), 0, 1)
    gap = np.hypot(*(buoys[:, None] - a - t[:, :, None] * (b - a)).transpose(2, 0, 1))
    ego = footprint_m(load_vessel_model("catabot"))
    assert gap.min() > ego + BUOY + CLEARANCE_M
    assert np.hypot(*(buoys - (0.0, 80.0)).T).min() > 6.0 + BUOY + CLEARANCE_M


def test_waypoints_of_the_default_region_are_drawn_on_the_terrain() -> None:
    """The default 1000 m region over the bundled 600 m bay drew two points in five off it,
    so 50 boats on waypoints found no paths ("no path of 5 waypoints ... in 5000 draws")."""
    world = World.resolve(parse_scenario({
        "seed": 3, "terrain": {"elevation_image": str(BAY), "min_elevation_m": -15.0,
                               "max_elevation_m": 25.0, "metres_per_pixel": 2.0},
        "vessels": [{"id": "ego"}],
        "traffic": {"count": 50, "behaviour_mix": {"waypoints": 1.0}},
    }))  # fmt: skip
    assert world.terrain is not None and world.terrain.size_m == (600.0, 600.0)
    points = np.array([p for boat in world.traffic.boats for p in boat.path])
    assert len(points) == 250 and (points >= 0).all() and (points <= 600).all()
