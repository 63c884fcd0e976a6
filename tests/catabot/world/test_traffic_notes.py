"""Notes on traffic set faster than its boats go (catabot/world/traffic_notes.py)."""

from __future__ import annotations

from typing import Any

from catabot.config.load import parse_scenario
from catabot.world.traffic_notes import speed_notes, traffic_notes
from catabot.world.world import World


def _notes(**traffic: Any) -> list[str]:
    data = {"name": "t", "duration_s": 1.0, "vessels": [{"id": "ego"}], "traffic": traffic}
    return speed_notes(World.resolve(parse_scenario(data)))


def test_boats_set_faster_than_they_go_are_said() -> None:
    """A trial's circle.speed_mps 8 was taken, and the monohulls held 5.96 m/s unsaid (the
    note said 6 before the top speed counted the still air's drag)."""
    (note,) = _notes(count=4, circle={"speed_mps": 8.0})
    assert note == (
        "note: traffic.circle.speed_mps 8: 4 circle boat(s) of model 'monohull' reach 5.96 m/s "
        "at most (full thrust against their damping), so they go that fast"
    )
    mixed = _notes(count=6, behaviour_mix={"circle": 0.5, "waypoints": 0.5},
                   waypoints={"speed_mps": 9.0, "buoys": False})  # fmt: skip
    assert [n.split(":")[1].strip() for n in mixed] == ["traffic.waypoints.speed_mps 9"]


def test_the_defaults_and_no_traffic_say_nothing() -> None:
    assert _notes(count=4) == []
    assert _notes(count=0, circle={"speed_mps": 8.0}) == []


def test_circles_tighter_than_the_traffic_can_turn_are_said() -> None:
    """A trial's 2-4 m circles at 5 m/s came out at 16 m without a word."""
    world = {"name": "t", "duration_s": 1.0, "vessels": [{"id": "ego"}]}
    tight = {"count": 3, "circle": {"radius_m": [2.0, 4.0]}}
    (note,) = traffic_notes(World.resolve(parse_scenario(world | {"traffic": tight})))
    assert note.startswith("note: traffic.circle.radius_m: 3 circling boat(s) with radii from 2")
    assert "at speed_mps 5 a traffic boat turns at most 0.35 rad/s" in note
    assert "a circle of 14.3 m at least" in note
    slow = {"count": 3, "circle": {"radius_m": [2.0, 4.0], "speed_mps": 0.5}}  # 1.4 m: fits
    assert traffic_notes(World.resolve(parse_scenario(world | {"traffic": slow}))) == []
    paths = tight | {"behaviour_mix": {"waypoints": 1.0}, "waypoints": {"buoys": False}}
    assert traffic_notes(World.resolve(parse_scenario(world | {"traffic": paths}))) == []
