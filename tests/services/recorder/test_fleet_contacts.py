"""The traffic's own collisions (services/recorder/fleet_contacts.py): the sweep finds every
pair a brute force finds, boxes touch as their geometry says, and episodes end after the gap;
then in metrics.json from a world with traffic."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from catabot.bus.messages import BodyStates
from catabot.config.load import parse_scenario
from catabot.world.hulls import CONTACT_M
from catabot.world.orders import Orders
from catabot.world.world import World
from services.recorder.fleet_contacts import FleetContacts, _near_pairs
from services.recorder.metrics import Metrics

HALF = np.array([[2.0, 1.0]])  # a 4 m x 2 m box about each body's origin


def test_the_sweep_finds_exactly_the_pairs_within_reach() -> None:
    rng = np.random.default_rng(3)
    xy, reach = rng.uniform(0.0, 60.0, (80, 2)), rng.uniform(0.5, 3.0, 80)
    a, b = _near_pairs(xy, reach)
    i, j = np.triu_indices(80, 1)
    near = np.hypot(*(xy[i] - xy[j]).T) <= reach[i] + reach[j] + CONTACT_M
    assert sorted(zip(a.tolist(), b.tolist(), strict=True)) == sorted(
        zip(i[near].tolist(), j[near].tolist(), strict=True)
    )
    assert all(a < b)


def _contacts(period: int = 1) -> FleetContacts:
    n = 4  # row 0 a scenario vessel, rows 1-3 traffic
    offset, half = np.zeros((n, 2)), np.repeat(HALF, n, axis=0)
    return FleetContacts(offset, half, np.hypot(*half.T), first=1, period=period, gap_ns=100)


def _batch(tick: int, xy: list[tuple[float, float]], yaw: list[float]) -> BodyStates:
    n = len(xy)
    pos = np.zeros((n, 3))
    pos[:, :2] = xy
    quat = np.zeros((n, 4))
    quat[:, 2], quat[:, 3] = np.sin(np.array(yaw) / 2), np.cos(np.array(yaw) / 2)
    z = np.zeros((n, 3))
    ids = tuple(f"b{k}" for k in range(n))
    return BodyStates(tick, tick * 10, ids, pos, quat, z, z, z, z)


def test_boxes_touch_as_their_headings_say() -> None:
    fleet = _contacts()
    end_on = [(0.0, 0.0), (0.0, 50.0), (4.0, 50.0), (0.0, 80.0)]  # 1 and 2 bow to stern
    a, b = fleet.touching(np.array(end_on[1:]), _batch(0, end_on, [0.0] * 4).orientation[1:])
    assert (a.tolist(), b.tolist()) == ([0], [1])
    turned = _batch(0, end_on, [0.0, np.pi / 2, np.pi / 2, 0.0])  # side by side, 4 m apart
    a, _ = fleet.touching(turned.position[1:, :2], turned.orientation[1:])
    assert a.size == 0


def test_an_episode_lasts_until_the_pair_has_been_apart_for_the_gap() -> None:
    fleet = _contacts()
    apart = [(0.0, 0.0), (0.0, 50.0), (9.0, 50.0), (0.0, 80.0)]
    touch = [(0.0, 0.0), (0.0, 50.0), (3.9, 50.0), (0.0, 80.0)]
    for tick, where in enumerate([apart, touch, touch, apart, touch, apart] + [apart] * 20):
        fleet.add(_batch(tick, where, [0.0] * 4))  # a 30 ns break is within the 100 ns gap
    (episode,) = fleet.all()
    assert episode.slot == (1, 2) and (episode.start_ns, episode.end_ns) == (10, 40)
    fleet.add(_batch(30, touch, [0.0] * 4))
    assert [e.end_ns for e in fleet.all()] == [40, None]  # a new one, still going


def test_only_the_recorded_ticks_are_checked_and_vessels_are_left_out() -> None:
    fleet = _contacts(period=10)
    touch = [(0.0, 50.0), (3.9, 50.0), (0.0, 80.0), (0.0, 0.0)]  # row 0 touches row 1
    fleet.add(_batch(5, touch, [0.0] * 4))
    assert fleet.all() == []  # not a recorded tick
    fleet.add(_batch(10, touch, [0.0] * 4))
    assert fleet.all() == []  # row 0 is a scenario vessel: its collisions are Metrics'


def test_metrics_json_lists_the_traffic_collisions(tmp_path: Path) -> None:
    scenario = {"name": "f", "vessels": [{"id": "ego", "pose": {"x_m": 0.0, "y_m": 0.0}}],
                "traffic": {"count": 2, "behaviour_mix": {"hold": 1.0}}}  # fmt: skip
    world = World.resolve(parse_scenario(scenario))
    metrics = Metrics(world, Orders())
    xy = [(0.0, 0.0), (40.0, 40.0), (40.5, 40.0)]  # the two boats on top of each other
    metrics.add(_batch(0, xy, [0.0] * 3))
    metrics.write(tmp_path / "metrics.json")
    record = json.loads((tmp_path / "metrics.json").read_text())
    assert record["traffic_collisions"] == [
        {"bodies": ["boat_000", "boat_001"], "start_s": 0.0, "end_s": None}
    ]
    assert record["vessels"]["ego"]["collisions"] == 0
