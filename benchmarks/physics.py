"""Physics step cost with every force on, against vessel count (dt 10 ms, one core).

A mixed fleet (catamarans and monohulls, both with added mass), a 50 x 50 current map on top
of a uniform current, gusty wind with a circle and a polygon zone, a moored buoy; once on
calm water and once with the "medium" sea state. Measures `PhysicsWorld.step()` plus reading
every state back (`state_arrays()`), best of three repeats.
"""

from __future__ import annotations

import time

import numpy as np

from catabot.config.environment import WindConfig, WindZone
from catabot.config.vessel import load_vessel_model
from catabot.config.waves import WaveConfig
from catabot.world.environment import CurrentField, WindField
from catabot.world.waves import WaveField
from services.physics.world import PhysicsWorld

COUNTS = (1, 10, 50, 100, 101, 200)
STEPS = 500
ZONES = [
    WindZone(shape="circle", center_m=(50, 50), radius_m=30, speed_mps=12, toward_rad=1.0),
    WindZone(
        shape="polygon",
        vertices_m=[(100, 0), (200, 0), (200, 80), (150, 40), (100, 80)],
        speed_mps=8,
    ),
]


def world_of(n: int, *, waves: bool) -> PhysicsWorld:
    models = [load_vessel_model("catabot"), load_vessel_model("monohull")]
    vessels = [
        (f"v{i}", models[i % 2], (12.0 * (i % 20), 12.0 * (i // 20), 0.0, 0.3 * i))
        for i in range(n)
    ]
    grid = np.random.default_rng(1).uniform(-0.3, 0.3, (50, 50, 2))
    world = PhysicsWorld(
        vessels,
        dt_s=0.01,
        current=CurrentField((0.2, 0.1), grid=grid, spacing_m=5.0),
        wind=WindField(WindConfig(speed_mps=6, gust_std_mps=1.5, zones=ZONES), seed=1),
        waves=WaveField(WaveConfig(preset="medium"), 1) if waves else None,
        buoys=[("b0", (-20.0, -20.0))],
    )
    for vid, _, _ in vessels:
        world.set_thrust(vid, (0.6, 0.7))
    return world


def step_cost(n: int, *, waves: bool) -> float:
    world = world_of(n, waves=waves)
    for _ in range(50):
        world.step()
    best = float("inf")
    for _ in range(3):
        start = time.perf_counter()
        for _ in range(STEPS):
            world.step()
            world.state_arrays()
        best = min(best, (time.perf_counter() - start) / STEPS)
    return best


def main() -> None:
    for waves in (False, True):
        sea = "medium waves" if waves else "calm water"
        print(f"\nPhysics step cost, every force on, {sea} (dt 10 ms, one core)")
        print(f"{'vessels':>7} | {'ms/step':>8} | {'steps/s':>8}")
        print(f"{'-' * 7}-|-{'-' * 8}-|-{'-' * 8}")
        for n in COUNTS:
            cost = step_cost(n, waves=waves)
            print(f"{n:>7} | {cost * 1e3:>8.3f} | {1 / cost:>8.0f}")


if __name__ == "__main__":
    main()
