"""Physics step cost with every force on, against vessel count (dt 10 ms, one core).

A mixed fleet (catamarans and monohulls, both with added mass), a 50 x 50 current map on top
of a uniform current, gusty wind with a circle and a polygon zone, a moored buoy; once on
calm water and once with the "medium" sea state. Measures `PhysicsWorld.step()` plus reading
every state back (`state_arrays()`), best of three repeats, in a process set up as every
service is (one BLAS thread, the kept heap). Then Table II's waypoint row in physics alone:
101 vessels at rest among 275 moored buoys once these sleep, against the vessels alone.

Reference beside it: bare DART, the same bodies in the same skeletons (fleet.py) stepped by
DART alone, no gravity and no forces, with their positions and velocities read back: what
any DART-based simulator of these bodies pays before hydrodynamics. Targets: 101 vessels at
>= 1000 steps/s on calm water; the medium swell at most 1.25x calm.
"""

from __future__ import annotations

import time
from collections.abc import Callable

import dartpy as dart
import numpy as np

from catabot.bus.blas import single_thread_blas
from catabot.bus.heap import keep_heap
from catabot.config.environment import WindConfig, WindZone
from catabot.config.vessel import VesselModel, load_vessel_model
from catabot.config.waves import WaveConfig
from catabot.world.environment import CurrentField, WindField
from catabot.world.waves import WaveField
from services.physics.fleet import Fleet
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


def fleet_of(n: int) -> list[tuple[str, VesselModel, tuple[float, float, float, float]]]:
    models = [load_vessel_model("catabot"), load_vessel_model("monohull")]
    return [
        (f"v{i}", models[i % 2], (12.0 * (i % 20), 12.0 * (i // 20), 0.0, 0.3 * i))
        for i in range(n)
    ]


def world_of(n: int, *, waves: bool) -> PhysicsWorld:
    vessels = fleet_of(n)
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


def timed(step: Callable[[], object]) -> float:
    """Seconds a call, best of three runs of STEPS after 50 to warm up."""
    for _ in range(50):
        step()
    best = float("inf")
    for _ in range(3):
        start = time.perf_counter()
        for _ in range(STEPS):
            step()
        best = min(best, (time.perf_counter() - start) / STEPS)
    return best


def step_cost(n: int, *, waves: bool) -> float:
    world = world_of(n, waves=waves)
    return timed(lambda: (world.step(), world.state_arrays()))


def resting_buoys_cost(buoys: int) -> tuple[float, int]:
    """101 vessels at rest among `buoys` moored buoys in a steady current and wind, after
    the buoys fell asleep (services/physics/sleep.py); and how many sleep."""
    vessels = fleet_of(101)
    xy = np.random.default_rng(3).uniform(300.0, 900.0, (buoys, 2))
    world = PhysicsWorld(
        vessels,
        dt_s=0.01,
        current=CurrentField((0.2, 0.1)),
        wind=WindField(WindConfig(speed_mps=3.0), seed=1),
        buoys=[(f"b{i}", (float(x), float(y))) for i, (x, y) in enumerate(xy)],
    )
    for _ in range(2500):  # the moorings' swing dies down in ~20 s
        world.step()
    return timed(lambda: (world.step(), world.state_arrays(), world.buoy_state_arrays())), int(
        world.asleep.sum()
    )


def bare_dart_cost(n: int) -> float:
    """The reference: the same bodies (and buoy) in DART alone, under way (2 m/s, turning
    at 0.2 rad/s). Why moving: DART recomputes a body's articulated inertia only when its
    pose changed, so bodies at rest stepped 3x cheaper (101 vessels 0.04 against 0.14 ms)
    than any floating fleet can."""
    models = fleet_of(n)
    fleet = Fleet([*models, ("b0", load_vessel_model("buoy"), (-20.0, -20.0, 0.0, 0.0))])
    world = dart.simulation.World()
    world.setGravity([0.0, 0.0, 0.0])
    world.setTimeStep(0.01)
    fleet.add_to(world)
    for skel in fleet.skeletons:  # per tree: [angular, linear] (fleet.py)
        skel.setVelocities(np.tile([0.0, 0.0, 0.2, 2.0, 0.0, 0.0], skel.getNumDofs() // 6))
    return timed(lambda: (world.step(), fleet.positions(), fleet.velocities()))


def main() -> None:
    single_thread_blas()  # as every service does (catabot/run/service.py)
    keep_heap()
    print("Physics step cost, every force on (dt 10 ms, one core), ms a step and steps/s")
    print("| vessels | bare DART | calm | steps/s | medium swell | steps/s | swell / calm |")
    print("|---:|---:|---:|---:|---:|---:|---:|")
    for n in COUNTS:
        bare, calm, swell = bare_dart_cost(n), step_cost(n, waves=False), step_cost(n, waves=True)
        print(f"| {n} | {bare * 1e3:.3f} | {calm * 1e3:.3f} | {1 / calm:.0f} | "
              f"{swell * 1e3:.3f} | {1 / swell:.0f} | {swell / calm:.2f} |")  # fmt: skip
    print(f"swell: {world_of(1, waves=True).sea_method}")
    alone, _ = resting_buoys_cost(0)
    among, asleep = resting_buoys_cost(275)
    print(f"101 vessels at rest: {alone * 1e3:.3f} ms a step; among 275 moored buoys, "
          f"{asleep} asleep: {among * 1e3:.3f} ms (+{(among - alone) * 1e3:.3f} ms)")  # fmt: skip
    print("targets: 101 vessels >= 1000 steps/s calm; swell / calm <= 1.25")


if __name__ == "__main__":
    main()
