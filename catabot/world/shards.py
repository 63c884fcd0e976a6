"""Which sensors process owns which sensor (`sensors.shards`).

Sensors go to shards by what they cost (rays a second), most expensive first, each to the
shard with the least work so far (longest-processing-time first: within 4/3 of the best
split), so one vessel's camera and LiDAR may run side by side; ties go to the lower index,
so every process derives the same split from the same world. The recording does not depend
on it: the recorder writes every stream in world order, whoever produced it, and each
sensor's noise has its own seed.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

from catabot.bus.clock import NS_PER_S
from catabot.config.sensors import shard_names

if TYPE_CHECKING:
    from catabot.world.world import MountedSensor

SERVICE = "sensors"
PER_SENSOR = 1e4  # rays a second a sensor is worth beside its rays (IMU, GPS: messages)


def sensor_costs(sensors: Sequence[MountedSensor], dt_ns: int) -> dict[str, float]:
    """Rays a second each sensor casts (by stream key, in world order)."""
    return {
        s.key: s.config.typed_params().rays_per_s(NS_PER_S / (s.period * dt_ns)) + PER_SENSOR
        for s in sensors
    }


def split(costs: dict[str, float], shards: int) -> dict[str, int]:
    """Sensor -> shard index: greedy, most expensive first, to the least loaded."""
    load = [0.0] * shards
    owner: dict[str, int] = {}
    order = sorted(enumerate(costs.items()), key=lambda item: (-item[1][1], item[0]))
    for _, (key, cost) in order:
        i = min(range(shards), key=lambda k: (load[k], k))
        owner[key] = i
        load[i] += cost
    return owner


def blocks(ids: Sequence[str], shards: int) -> list[tuple[str, ...]]:
    """Contiguous blocks of nearly equal size, in order: a traffic shard's boats. Contiguous,
    so the recorder meets every boat in the same order whatever the number of shards."""
    n = len(ids)
    return [tuple(ids[i * n // shards : (i + 1) * n // shards]) for i in range(shards)]


def sensor_owners(sensors: Sequence[MountedSensor], shards: int, dt_ns: int) -> dict[str, str]:
    """Sensor stream key -> the participant that produces it."""
    names = shard_names(SERVICE, shards)
    owner = split(sensor_costs(sensors, dt_ns), shards)
    return {key: names[i] for key, i in owner.items()}
