"""The Gymnasium env's speed: env steps per second, one world and four, state only and with
a LiDAR observation, beside the bare run of the same scenario; and where the time goes.

`CataBot/Navigate-v0` (the bundled `navigate` scenario: the bay terrain, five buoys, a
light current, a steady wind; physics at 100 Hz, control at 10 Hz: one env step = 10
ticks), a constant forward action, one long episode per cell (no reset inside the
measurement), timed after a warm-up. The reference is `catabot run` of the very scenario an
episode runs, with the ego scripted instead of driven by the env (no external participant,
nothing recorded), its ticks/s divided by the 10 ticks of a control period. Four worlds run
as Gymnasium's AsyncVectorEnv (a process each, each world its own run, port and key prefix)
and SyncVectorEnv (one process); a vector step is four env steps. Resets: the median wall
time of a reset (a fresh run each), and with `prelaunch` (the next episode's run started
while the current one plays). Target (issue 15): >= 200 env steps/s, one world, state only.

Usage: python -m benchmarks.gym [seconds] (default 20 s a cell), or `python -m benchmarks gym`.
"""

from __future__ import annotations

import statistics
import sys
import time

import gymnasium as gym
import numpy as np

import catabot.gym  # noqa: F401 - registers the envs
from benchmarks.gym_parts import Breakdown, bare_periods_per_s, steps_per_s, vector_steps_per_s

TARGET = 200.0
ENV = "CataBot/Navigate-v0"
LONG = 1_000_000  # steps: no episode ends inside a cell
OPEN = "default"  # the bundled open-water scenario: one catamaran, calm, no terrain


def resets(n: int, *, prelaunch: bool) -> float:
    """Median wall seconds of a reset; seedless after the first, as a training loop does."""
    env = gym.make(ENV, max_steps=5, prelaunch=prelaunch)
    times = []
    try:
        env.reset(seed=0)
        for _ in range(n):
            for _ in range(5):
                env.step(np.array([0.5, 0.5], np.float32))
            time.sleep(3.0)  # an episode's play: the prelaunched run gets ready meanwhile
            started = time.perf_counter()
            env.reset()
            times.append(time.perf_counter() - started)
    finally:
        env.close()
    return statistics.median(times)


def main(argv: list[str] | None = None) -> None:
    args = sys.argv[1:] if argv is None else argv
    numbers = [float(a) for a in args if a.replace(".", "", 1).isdigit()]
    seconds = numbers[0] if numbers else 20.0
    print(f"Gymnasium env ({ENV}, 10 Hz control, 100 Hz physics), {seconds:g} s a cell")
    bare = bare_periods_per_s(seconds)
    one = steps_per_s(ENV, seconds, max_steps=LONG)
    open_bare = bare_periods_per_s(seconds, scenario=OPEN)
    open_one = steps_per_s(ENV, seconds, max_steps=LONG, scenario=OPEN, breakdown=True)
    lidar = steps_per_s(ENV, seconds, max_steps=LONG, sensors=["lidar"])
    asyn = vector_steps_per_s(ENV, 4, seconds, asynchronous=True, max_steps=LONG)
    syn = vector_steps_per_s(ENV, 4, seconds, asynchronous=False, max_steps=LONG)
    asyn_lidar = vector_steps_per_s(
        ENV, 4, seconds, asynchronous=True, max_steps=LONG, sensors=["lidar"]
    )
    reset_cold, reset_pre = resets(5, prelaunch=False), resets(5, prelaunch=True)
    met = "met" if open_one.rate >= TARGET else "not met"
    print()
    print("| what | env steps/s | control periods/s of the bare run | target |")
    print("|---|---:|---:|---|")
    share = open_one.rate / open_bare
    print(f"| 1 world, state only, open water | **{open_one.rate:.0f}** | {open_bare:.0f} | "
          f">= {TARGET:.0f}: {met} ({share:.2f} of the bare run) |")  # fmt: skip
    print(f"| 1 world, state only, the bay | {one.rate:.0f} | {bare:.0f} | |")
    print(f"| 1 world, state + LiDAR 16 x 64 | {lidar.rate:.0f} | | |")
    print(f"| 4 worlds, AsyncVectorEnv, state only | {asyn:.0f} (4 x {asyn / 4:.0f}) | | |")
    print(f"| 4 worlds, SyncVectorEnv, state only | {syn:.0f} (4 x {syn / 4:.0f}) | | |")
    print(f"| 4 worlds, AsyncVectorEnv, state + LiDAR | {asyn_lidar:.0f} | | |")
    print(f"| reset (a fresh run), median | {reset_cold:.2f} s | | |")
    print(f"| reset with prelaunch, median | {reset_pre:.2f} s | | |")
    print()
    print_breakdown(open_one.breakdown)


def print_breakdown(b: Breakdown | None) -> None:
    if b is None:
        return
    print("Where the time of one env step goes (1 world, state only, open water; ms a step):")
    print()
    print("| part | ms | what |")
    print("|---|---:|---|")
    for name, ms, what in b.rows():
        print(f"| {name} | {ms:.3f} | {what} |")


if __name__ == "__main__":
    main()
