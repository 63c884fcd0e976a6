"""Physics step cost against vessel count: every force vectorised, one DART world.

Measures what the physics service pays per tick before publishing: forces for every
vessel, `World.step`, and reading all states back.
"""

from __future__ import annotations

import math
import time

from catabot.vessel import load_vessel_model
from services.physics.world import PhysicsWorld

COUNTS = (1, 10, 50, 100, 200)
STEPS = 1000


def world_of(n: int) -> PhysicsWorld:
    model = load_vessel_model("catabot")
    side = math.ceil(math.sqrt(n))
    vessels = [
        (f"v{i}", model, (12.0 * (i % side), 12.0 * (i // side), 0.0, 0.3 * i)) for i in range(n)
    ]
    world = PhysicsWorld(vessels, dt_s=0.01)
    for i, (vid, _, _) in enumerate(vessels):
        world.set_thrust(vid, (0.5 + 0.01 * (i % 10), 0.6))
    return world


def step_cost(n: int) -> float:
    world = world_of(n)
    for _ in range(50):
        world.step()
    start = time.perf_counter()
    for _ in range(STEPS):
        world.step()
        world.state_arrays()
    return (time.perf_counter() - start) / STEPS


def main() -> None:
    print("\nPhysics step cost (catamaran model, dt 10 ms, one core)")
    print(f"{'vessels':>7} | {'ms/step':>8} | {'steps/s':>8} | {'real-time factor':>16}")
    print(f"{'-' * 7}-|-{'-' * 8}-|-{'-' * 8}-|-{'-' * 16}")
    for n in COUNTS:
        cost = step_cost(n)
        print(f"{n:>7} | {cost * 1e3:>8.3f} | {1 / cost:>8.0f} | {0.01 / cost:>16.1f}")


if __name__ == "__main__":
    main()
