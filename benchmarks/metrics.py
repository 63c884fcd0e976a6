"""The recorder's navigation metrics: CPU per tick of `Metrics.add` with Table II's 100 boats.

The world of Table II's last row (the ego, 100 boats half on waypoint paths, a buoy at each
waypoint) on the bundled harbour terrain; the bodies move along straight lines (the cost does
not depend on where they are, only on how many are near one another). Prints the median of
`REPEATS` timings of `TICKS` ticks, in microseconds per tick.
"""

from __future__ import annotations

import time

import numpy as np

from benchmarks.table2 import MIX, scenario
from catabot.bus.messages import BodyStates
from catabot.config.load import parse_scenario
from catabot.world.world import World
from services.recorder.metrics import Metrics

TICKS = 500
REPEATS = 5


def batches(world: World, ticks: int) -> list[BodyStates]:
    """States of every body at `ticks` ticks, each body drifting at its own velocity."""
    start = world.start_states()
    rng = np.random.default_rng(0)
    n = len(world.body_ids)
    vel = np.zeros((n, 3))
    vel[: len(world.vessels), :2] = rng.normal(0.0, 3.0, (len(world.vessels), 2))
    dt = world.scenario.dt_ns / 1e9
    out = []
    for k in range(ticks):
        pos = start.position + vel * dt * (k + 1)
        z = np.zeros((n, 3))
        stamp = (k + 1) * world.scenario.dt_ns
        out.append(BodyStates(k, stamp, world.body_ids, pos, start.orientation, vel, z, z, z))
    return out


def per_tick_us(world: World) -> float:
    states = batches(world, TICKS)
    times = []
    for _ in range(REPEATS):
        metrics = Metrics(world)
        t0 = time.process_time()
        for batch in states:
            metrics.add(batch)
        times.append((time.process_time() - t0) / TICKS * 1e6)
    return float(np.median(times))


def main() -> None:
    data = scenario(100, 0, 60.0, MIX)
    data["terrain"] = {"elevation_image": "catabot/data/terrain/bay.png", "min_elevation_m": -15.0,
                       "max_elevation_m": 25.0, "metres_per_pixel": 10.0}  # fmt: skip
    data["vessels"][0]["pose"] = {"x_m": 1500.0, "y_m": 1500.0}
    data["vessels"][0]["task"] = {"goal": {"x_m": 1600.0, "y_m": 1500.0, "radius_m": 5.0},
                                  "route": [[1500.0, 1500.0], [1600.0, 1500.0]]}  # fmt: skip
    data["traffic"]["region"] = {"center_m": [1500.0, 1500.0], "size_m": [500.0, 500.0]}
    world = World.resolve(parse_scenario(data))
    bodies = len(world.body_ids)
    print(f"metrics: {len(world.vessels)} vessels, {bodies - len(world.vessels)} buoys, "
          f"{per_tick_us(world):.1f} us per tick (Metrics.add, median of {REPEATS})")  # fmt: skip
