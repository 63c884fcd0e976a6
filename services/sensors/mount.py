"""Where a sensor runs: everything a model is built with besides its own parameters.

Every model is `Model(params, mount)` (the sensor registry's entry points, catabot.config
.sensors): `params` is the type's validated parameters, `mount` says whose sensor it is (the
name its noise is seeded with, `<vessel>/<sensor>`), the scenario seed, whether noise is on,
its period, the shared ray-casting scene and the world's geodetic origin.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from catabot.config.scenario import Origin


@dataclass(frozen=True)
class Mount:
    name: str = "sensor"  # the random source's name (catabot.world.seeding)
    seed: int = 0
    noise: bool = True
    period_ns: int = 0
    tick_ns: int = 0  # the physics tick (0: unknown): an IMU slower than it averages (imu.py)
    scene: Any = None  # services.sensors.scene.Scene for the ray-casting types
    origin: Origin = field(default_factory=Origin)
