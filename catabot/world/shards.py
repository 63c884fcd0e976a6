"""Which sensors process owns which vessel's sensors (`sensors.shards`).

A shard owns whole vessels, so the vessel's sensors share one scene pose and one state row.
Vessels go to shards by what their sensors cost, most expensive first, each to the shard
with the least work so far (longest-processing-time first: within 4/3 of the best split);
ties go to the lower index, so every process derives the same split from the same world.
The recording does not depend on it: the recorder writes every stream in world order,
whoever produced it.
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


def vessel_costs(sensors: Sequence[MountedSensor], dt_ns: int) -> dict[str, float]:
    """Rays a second each sensor-carrying vessel's sensors cast, in world order."""
    costs: dict[str, float] = {}
    for s in sensors:
        rate_hz = NS_PER_S / (s.period * dt_ns)
        cost = s.config.typed_params().rays_per_s(rate_hz) + PER_SENSOR
        costs[s.vessel] = costs.get(s.vessel, 0.0) + cost
    return costs


def split(costs: dict[str, float], shards: int) -> dict[str, int]:
    """Vessel -> shard index: greedy, most expensive vessel first, to the least loaded."""
    load = [0.0] * shards
    owner: dict[str, int] = {}
    order = sorted(enumerate(costs.items()), key=lambda item: (-item[1][1], item[0]))
    for _, (vessel, cost) in order:
        i = min(range(shards), key=lambda k: (load[k], k))
        owner[vessel] = i
        load[i] += cost
    return owner


def sensor_owners(sensors: Sequence[MountedSensor], shards: int, dt_ns: int) -> dict[str, str]:
    """Sensor stream key -> the participant that produces it."""
    names = shard_names(SERVICE, shards)
    owner = split(vessel_costs(sensors, dt_ns), shards)
    return {s.key: names[owner[s.vessel]] for s in sensors}
