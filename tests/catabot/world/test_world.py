"""The resolved world: bodies and rows, sensors, streams, participants, refusals."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from catabot.bus.keys import Keys
from catabot.bus.messages import BodyStates, GpsFix, ImuSample
from catabot.config.base import ScenarioError
from catabot.config.load import parse_scenario
from catabot.config.vessel import load_vessel_model
from catabot.world.world import World

KEYS = Keys("w")


def _world(**changes: object) -> World:
    data = {
        "name": "w",
        "vessels": [
            {
                "id": "ego",
                "sensors": [
                    {"name": "imu", "type": "imu", "rate_hz": 100.0},
                    {"name": "gps", "type": "gps", "rate_hz": 10.0},
                ],
            },
            {"id": "buoy"},
        ],
    }
    data.update(changes)
    return World.resolve(parse_scenario(data))


def test_participants() -> None:
    assert _world().participants[:3] == ["physics", "sensors", "recorder"]
    assert "sensors" not in _world(vessels=[{"id": "a"}]).participants
    no_recording = _world(recording={"csv": False, "mcap": False})
    assert "recorder" not in no_recording.participants
    assert no_recording.participants[:2] == ["physics", "sensors"]


def test_lockstep_streams() -> None:
    streams = _world().streams.lockstep()
    table = {s.key: (s.message, s.producer, s.period) for s in streams}
    assert table == {
        KEYS.world_states(): (BodyStates, "physics", 1),
        KEYS.sensor("ego", "imu"): (ImuSample, "sensors", 1),
        KEYS.sensor("ego", "gps"): (GpsFix, "sensors", 10),
    }
    assert len(streams) == len(table)


def test_per_vessel_states_are_for_observers_only() -> None:
    """Lockstep consumers wait for the one batch; per-vessel states stay off the table."""
    world = _world()  # two vessels ("buoy" is a vessel's id here), no moored buoys
    assert KEYS.world_states() == "catabot/w/world/states"
    states = [s.key for s in world.streams.vessel_states]
    assert states == [KEYS.vessel_state("ego"), KEYS.vessel_state("buoy")]
    assert world.body_ids == ("ego", "buoy")
    lockstep = {s.key for s in world.streams.lockstep()}
    assert not lockstep & {KEYS.vessel_state("ego"), KEYS.vessel_state("buoy")}


def test_the_states_stream_refuses_other_rows_or_shapes() -> None:
    def batch(ids: tuple[str, ...], n: int | None = None) -> BodyStates:
        z3, z4 = np.zeros((n or len(ids), 3)), np.zeros((n or len(ids), 4))
        return BodyStates(0, 0, ids, z3, z4, z3, z3, z3, z3)

    check = _world().streams.states.check
    assert check is not None
    check(batch(("ego", "buoy")))
    with pytest.raises(ValueError, match="expected"):
        check(batch(("buoy", "ego")))
    with pytest.raises(ValueError, match=r"position is float64 \(3, 3\), not float64 \(2, 3\)"):
        check(batch(("ego", "buoy"), n=3))


def test_rows_are_vessels_then_boats_then_buoys() -> None:
    world = _world(
        vessels=[{"id": "ego"}],
        buoys=[{"id": "mark", "x_m": 40.0, "y_m": 0.0}],
        traffic={"count": 3, "behaviour_mix": {"waypoints": 1.0}},
    )
    kinds = [b.kind for b in world.bodies]
    assert kinds[:4] == ["vessel", "boat", "boat", "boat"] and set(kinds[4:]) == {"buoy"}
    assert world.body_ids[4] == "mark"  # the scenario's buoys before the plan's
    assert [b.row for b in world.bodies] == list(range(len(world.bodies)))
    assert world.boat_ids == ("boat_000", "boat_001", "boat_002")
    assert [b.instance for b in world.bodies] == [b.row + 1 for b in world.bodies]
    assert [s.producer for s in world.streams.twists] == ["traffic"]


def test_start_states_are_the_start_poses_at_rest() -> None:
    world = _world(vessels=[{"id": "ego", "pose": {"x_m": 3.0, "y_m": -2.0, "yaw_rad": 1.0}}])
    start = world.start_states()
    assert start.tick == -1 and start.ids == ("ego",)
    assert start.position.tolist() == [[3.0, -2.0, 0.0]]
    assert start.orientation[0, 2:] == pytest.approx([np.sin(0.5), np.cos(0.5)])
    assert not start.linear_velocity.any()


@pytest.mark.parametrize(
    ("changes", "message"),
    [
        ({"buoys": [{"id": "ego", "x_m": 30.0, "y_m": 0.0}]}, "body id 'ego' is used twice"),
        ({"vessels": [{"id": "boat_000"}], "traffic": {"count": 1}}, "'boat_000' is used twice"),
    ],
)
def test_two_bodies_with_one_id_are_refused(changes: dict[str, Any], message: str) -> None:
    with pytest.raises(ScenarioError, match=message):
        _world(**changes)


@pytest.mark.parametrize("mass_kg", [55.0, 400.0])
def test_a_model_heavier_than_its_hulls_displace_is_refused(tmp_path: Path, mass_kg: float) -> None:
    """The catamaran's pontoons displace 2 x 1.9 x 0.24 x 0.30 m^3 x 1025 kg/m^3 = 280 kg
    wholly under water: at 55 kg it floats, at 400 kg it would sink to the bottom unreported."""
    model = json.loads(load_vessel_model("catabot").model_dump_json()) | {"mass_kg": mass_kg}
    (tmp_path / "cat.json").write_text(json.dumps(model))
    data = {"vessels": [{"id": "ego", "model": str(tmp_path / "cat.json")}]}
    if mass_kg < 280.0:
        World.resolve(parse_scenario(data))
        return
    said = r"vessels.0.model \(ego\): vessel model '.*cat.json' cannot float: its mass 400 kg "
    with pytest.raises(ScenarioError, match=said + r"is more than its hulls displace wholly") as e:
        World.resolve(parse_scenario(data))
    assert "under water (280 kg in water of 1025 kg/m^3)" in str(e.value)
