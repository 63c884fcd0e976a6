"""The recorder's navigation metrics: CPU per tick of `Metrics.add` with Table II's 100 boats.

The world of Table II's last row (the ego, 100 boats half on waypoint paths, a buoy at each
waypoint) on the bundled bay terrain, with a goal and a route for the ego. The boats drift
along straight lines. Two cases: the ego at rest, as in Table II (most figures cannot change:
the cheap path), and the ego driving at 3 m/s towards the shore (the nearest shore, boat and
buoy improve every tick: every lookup is made). Prints the best of `REPEATS` timings of
`TICKS` ticks (process CPU time), in microseconds per tick.
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


def batches(world: World, ticks: int, ego_mps: float) -> list[BodyStates]:
    """States of every body at `ticks` ticks, each boat drifting at its own velocity, the ego
    heading east (towards the bay's east shore) at `ego_mps`."""
    start = world.start_states()
    rng = np.random.default_rng(0)
    n = len(world.body_ids)
    vel = np.zeros((n, 3))
    vel[: len(world.vessels), :2] = rng.normal(0.0, 3.0, (len(world.vessels), 2))
    vel[0] = (ego_mps, 0.0, 0.0)
    dt = world.scenario.dt_ns / 1e9
    out = []
    for k in range(ticks):
        pos = start.position + vel * dt * (k + 1)
        z = np.zeros((n, 3))
        stamp = (k + 1) * world.scenario.dt_ns
        out.append(BodyStates(k, stamp, world.body_ids, pos, start.orientation, vel, z, z, z))
    return out


def per_tick_us(world: World, ego_mps: float) -> float:
    states = batches(world, TICKS, ego_mps)
    times = []
    for _ in range(REPEATS):
        metrics = Metrics(world)
        t0 = time.process_time()
        for batch in states:
            metrics.add(batch)
        times.append((time.process_time() - t0) / TICKS * 1e6)
    return min(times)


def main() -> None:
    data = scenario(100, 0, 60.0, MIX)
    data["terrain"] = {"elevation_image": "catabot/data/terrain/bay.png", "min_elevation_m": -15.0,
                       "max_elevation_m": 25.0, "metres_per_pixel": 10.0}  # fmt: skip
    data["vessels"][0]["pose"] = {"x_m": 1500.0, "y_m": 1500.0}
    data["vessels"][0]["task"] = {"goal": {"x_m": 1600.0, "y_m": 1500.0, "radius_m": 5.0},
                                  "route": [[1500.0, 1500.0], [1600.0, 1500.0]]}  # fmt: skip
    data["traffic"]["region"] = {"center_m": [1500.0, 1500.0], "size_m": [500.0, 500.0]}
    world = World.resolve(parse_scenario(data))
    buoys = len(world.body_ids) - len(world.vessels)
    print(f"metrics ({len(world.vessels)} vessels, {buoys} buoys), Metrics.add per tick, "
          f"best of {REPEATS}:")  # fmt: skip
    for label, mps in (("ego at rest", 0.0), ("ego driving shorewards", 3.0)):
        print(f"  {label:26s} {per_tick_us(world, mps):6.1f} us")


if __name__ == "__main__":
    main()
