"""Sensor models by type: the registry's entry points (catabot.config.sensors), imported once.

Every model is `Model(params, mount)` and draws its noise from `seeding.rng(seed,
"<vessel>/<sensor>")`, so a sensor's samples stay the same when sensors are added, removed
or moved between processes.
"""

from __future__ import annotations

import importlib
from typing import Any, Protocol

from catabot.bus.messages import Message, VesselState
from catabot.config.sensors import SENSOR_TYPES
from catabot.world.world import MountedSensor, World
from services.sensors.common import SensorError
from services.sensors.mount import Mount


class Sensor(Protocol):
    """What the sensors service needs of a model: its message type and one sample."""

    @property
    def message(self) -> type[Message]: ...

    def sample(self, state: VesselState, *, tick: int, stamp_ns: int) -> Message: ...


def model_class(type_name: str) -> Any:
    """The model class of a registered sensor type, from its `module:Class` entry point."""
    spec = SENSOR_TYPES.get(type_name)
    if spec is None:
        raise SensorError(f"unknown sensor type {type_name!r} (known: {sorted(SENSOR_TYPES)})")
    module, _, name = spec.entry_point.partition(":")
    return getattr(importlib.import_module(module), name)


def build_sensor(sensor: MountedSensor, world: World, *, scene: Any = None) -> Sensor:
    """The model of one mounted sensor of the world."""
    scenario = world.scenario
    mount = Mount(
        name=sensor.seed_name,
        seed=scenario.seed,
        noise=sensor.config.noise,
        period_ns=sensor.config.period_ns,
        tick_ns=scenario.dt_ns,
        scene=scene,
        origin=scenario.origin,
    )
    model: Sensor = model_class(sensor.config.type)(sensor.params, mount)
    return model
