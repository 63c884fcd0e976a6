"""A world to describe: two vessels, one driven by a lockstep stack, sensors with mounts,
traffic and buoys; and the `world/info` answer of it, as the conductor serves it."""

from __future__ import annotations

import json
import math
from typing import Any

from catabot.bus.identity import Roster, new_zid
from catabot.config.load import parse_scenario
from catabot.config.scenario import Scenario
from catabot.run.world_info import describe
from catabot.world.world import World

ROSTER = Roster({"conductor": new_zid(), "physics": new_zid(), "sensors": new_zid()})


def scenario(name: str = "info", **top: Any) -> Scenario:
    lidar = {"name": "lidar", "type": "lidar", "rate_hz": 10.0,
             "params": {"mount_xyz": [0.5, 0.0, 1.5], "mount_yaw_deg": 90.0,
                        "mount_pitch_deg": -10.0}}  # fmt: skip
    ego = {"id": "ego", "pose": {"x_m": 3.0, "y_m": 4.0, "yaw_rad": 0.5},
           "controller": {"participant": "stack", "rate_hz": 20.0, "command": "twist"},
           "sensors": [{"name": "gps", "type": "gps", "rate_hz": 5.0}, lidar]}  # fmt: skip
    data = {"name": name, "seed": 5, "duration_s": 2.0, "vessels": [ego, {"id": "other"}],
            "buoys": [{"id": "b1", "x_m": 30.0, "y_m": -5.0}],
            "traffic": {"count": 2},
            "clock": {"external_participants": ["watcher"]}, **top}  # fmt: skip
    return parse_scenario(data, source="test")


def answer(name: str = "info", granted: int = -1) -> dict[str, Any]:
    """The JSON a client receives (through a JSON round trip, as on the wire)."""
    data = describe(World.resolve(scenario(name)), ROSTER)
    return dict(json.loads(json.dumps({**data, "granted": granted})))


DEG = math.pi / 180
