"""Physics step cost with every force on, against vessel count (dt 10 ms, one core).

A mixed fleet (catamarans and monohulls, both with added mass), a 50 x 50 current map on top
of a uniform current, gusty wind with a circle and a polygon zone, a moored buoy; once on
calm water and once with the "medium" sea state. Measures `PhysicsWorld.step()` plus reading
every state back (`state_arrays()`), in a process set up as every service is (one BLAS
thread, the kept heap). A shared machine's speed drifts by tens of percent from one second
to the next, so bare DART, calm and swell are timed in interleaved blocks (ROUNDS of them,
each STEPS steps of each world in turn), and each figure is the median over rounds; the
swell / calm ratio is the median of each round's own ratio, both worlds timed within the
same second or two. Then Table II's waypoint row in physics alone:
101 vessels at rest among 275 moored buoys once these sleep, against the vessels alone.

Reference beside it: bare DART, the same bodies in the same skeletons (fleet.py) stepped by
DART alone, no gravity and no forces, with their positions and velocities read back: what
any DART-based simulator of these bodies pays before hydrodynamics. Targets: 101 vessels at
>= 1000 steps/s on calm water; the medium swell at most 1.25x calm.
"""

from __future__ import annotations

import statistics
import time
from collections.abc import Callable, Sequence

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
STEPS = 300  # steps a block
ROUNDS = 7  # blocks of each world, interleaved
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


def warm(step: Callable[[], object]) -> Callable[[], object]:
    for _ in range(50):
        step()
    return step


def block(step: Callable[[], object], steps: int = STEPS) -> float:
    """Seconds a call over one block of `steps` calls."""
    start = time.perf_counter()
    for _ in range(steps):
        step()
    return (time.perf_counter() - start) / steps


def interleaved(steps: Sequence[Callable[[], object]]) -> list[list[float]]:
    """ROUNDS blocks of each of `steps` in turn: [round][which] seconds a call."""
    warmed = [warm(step) for step in steps]
    return [[block(step) for step in warmed] for _ in range(ROUNDS)]


def stepper(n: int, *, waves: bool) -> Callable[[], object]:
    world = world_of(n, waves=waves)

    def step() -> None:
        world.step()
        world.state_arrays()

    return step


def resting_buoys(buoys: int) -> tuple[Callable[[], object], int]:
    """A step of 101 vessels at rest among `buoys` moored buoys in a steady current and
    wind, after the buoys fell asleep (services/physics/sleep.py); and how many sleep."""
    vessels = fleet_of(101)
    xy = np.random.default_rng(3).uniform(300.0, 900.0, (buoys, 2))
    world = PhysicsWorld(
        vessels,
        dt_s=0.01,
        current=CurrentField((0.2, 0.1)),
        wind=WindField(WindConfig(speed_mps=3.0), seed=1),
        buoys=[(f"b{i}", (float(x), float(y))) for i, (x, y) in enumerate(xy)],
    )
    for _ in range(4500):  # the moorings' slow swing (loads.py) dies down in 35-40 s
        world.step()

    def step() -> None:
        world.step()
        world.state_arrays()
        world.buoy_state_arrays()

    return step, int(world.asleep.sum())


def bare_dart(n: int) -> Callable[[], object]:
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
    return lambda: (world.step(), fleet.positions(), fleet.velocities())


def row(n: int) -> tuple[str, str]:
    """One table row: the medians over interleaved rounds (see the module's docstring), and
    what it says against the targets (judged at 101 vessels)."""
    rounds = interleaved([bare_dart(n), stepper(n, waves=False), stepper(n, waves=True)])
    bare, calm, swell = (statistics.median(r[i] for r in rounds) for i in range(3))
    ratio = statistics.median(r[2] / r[1] for r in rounds)
    text = (f"| {n} | {bare * 1e3:.3f} | {calm * 1e3:.3f} | {1 / calm:.0f} | "
            f"{swell * 1e3:.3f} | {1 / swell:.0f} | {ratio:.2f} |")  # fmt: skip
    verdict = (f"{n} vessels: calm {1 / calm:.0f} steps/s, {calm / bare:.1f} x bare DART "
               f"(>= 1000 steps/s: {_met(1 / calm >= 1000)}, this machine's speed decides it); "
               f"swell / calm {ratio:.2f} (<= 1.25: {_met(ratio <= 1.25)})")  # fmt: skip
    return text, verdict


def _met(ok: bool) -> str:
    return "met" if ok else "NOT met"


def main() -> None:
    single_thread_blas()  # as every service does (catabot/run/service.py)
    keep_heap()
    print("Physics step cost, every force on (dt 10 ms, one core), ms a step and steps/s;")
    print(f"medians over {ROUNDS} interleaved rounds of {STEPS} steps of each world")
    print("| vessels | bare DART | calm | steps/s | medium swell | steps/s | swell / calm |")
    print("|---:|---:|---:|---:|---:|---:|---:|")
    verdicts = {}
    for n in COUNTS:
        text, verdicts[n] = row(n)
        print(text, flush=True)
    print(f"swell: {world_of(1, waves=True).sea_method}")
    (alone, _), (among, asleep) = resting_buoys(0), resting_buoys(275)
    rounds = interleaved([alone, among])
    ms_alone, ms_among = (1e3 * statistics.median(r[i] for r in rounds) for i in range(2))
    print(f"101 vessels at rest: {ms_alone:.3f} ms a step; among 275 moored buoys, "
          f"{asleep} asleep: {ms_among:.3f} ms (+{ms_among - ms_alone:.3f} ms)")  # fmt: skip
    print(f"targets: {verdicts[101]}")


if __name__ == "__main__":
    main()
