"""Measurements behind `python -m benchmarks gym`: the bare run, env steps/s with the CPU of
every process of the run and of the env's own threads, and vector envs."""

from __future__ import annotations

import json
import subprocess
import sys
import tempfile
import threading
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np
import psutil
from gymnasium.utils import seeding

from catabot.gym import CataBotEnv
from catabot.gym.env import SEED_HIGH
from catabot.gym.episode import Draw
from catabot.gym.options import env_options
from catabot.gym.runner import Runner

WARMUP = 30  # steps before the clock starts
SEED = 1
NEVER_THERE = {"goal_radius_m": 1e-3}  # no episode ends at its goal inside a cell
FORWARD = [0.5, 0.45]


def bare_periods_per_s(seconds: float, **options: Any) -> float:
    """The scenario of the episode the env plays after reset(seed=SEED), run by `catabot
    run` with the ego scripted (no env, no external participant, nothing recorded), about
    `seconds` of wall time: lockstep ticks/s (run.json: start-up excluded) over the 10 ticks
    of a control period."""
    episode_seed = int(seeding.np_random(SEED)[0].integers(0, SEED_HIGH))
    scenario = Draw(env_options(**options)).episode(episode_seed, "gym_bare").scenario
    data = scenario.model_dump(mode="json")
    ego = data["vessels"][0]
    ego["controller"], ego["script"] = None, [{"t_s": 0.0, "thrust": FORWARD}]
    data["duration_s"] = 10.0 * seconds  # the bare run steps 10-20 simulated s a second
    with tempfile.TemporaryDirectory(prefix="gym-bare-") as tmp:
        path = Path(tmp) / "bare.json"
        path.write_text(json.dumps(data))
        cmd = [sys.executable, "-m", "catabot", "run", str(path), "--quiet", "--out", tmp]
        subprocess.run(cmd, capture_output=True, check=True, stdin=subprocess.DEVNULL)
        (result,) = [json.loads(p.read_text()) for p in Path(tmp).glob("*/log/run.json")]
    ticks_per_s = float(result["ticks"]) / float(result["wall_s"])
    label = ", ".join(f"{k}={v}" for k, v in options.items()) or "Navigate-v0's scenario"
    print(f"  bare run ({label}): {ticks_per_s:.0f} ticks/s = {ticks_per_s / 10:.0f} "
          "control periods/s", flush=True)  # fmt: skip
    return ticks_per_s / 10


@dataclass
class Breakdown:
    steps: int
    wall_s: float
    main_cpu_s: float
    lockstep_cpu_s: float
    process_cpu_s: float
    waiting_s: float
    run_cpu_s: dict[str, float]

    def __add__(self, other: Breakdown) -> Breakdown:
        run = {k: self.run_cpu_s.get(k, 0.0) + other.run_cpu_s.get(k, 0.0)
               for k in {**self.run_cpu_s, **other.run_cpu_s}}  # fmt: skip
        return Breakdown(
            self.steps + other.steps, self.wall_s + other.wall_s,
            self.main_cpu_s + other.main_cpu_s, self.lockstep_cpu_s + other.lockstep_cpu_s,
            self.process_cpu_s + other.process_cpu_s, self.waiting_s + other.waiting_s, run,
        )  # fmt: skip

    def rows(self) -> list[tuple[str, float, str]]:
        per = 1000.0 / self.steps
        zenoh = self.process_cpu_s - self.main_cpu_s - self.lockstep_cpu_s
        rows = [
            ("env step, wall", self.wall_s * per, "what an agent waits for one step"),
            ("env: waiting in observe()", self.waiting_s * per,
             "the env's thread blocked until the next control tick's inputs are in"),
            ("env: main thread CPU", self.main_cpu_s * per,
             "Gymnasium wrappers, action check, command, observation, reward, hand-over"),
            ("env: lockstep thread CPU", self.lockstep_cpu_s * per,
             "the client's participant: 10 BodyStates a step decoded, acks, the command"),
            ("env: Zenoh's threads CPU", zenoh * per, "receiving and sending in the env"),
        ]  # fmt: skip
        rows += [(f"{name} CPU", cpu * per, what) for name, (cpu, what) in self._run().items()]
        total = self.process_cpu_s + sum(self.run_cpu_s.values())
        rows.append(("CPU of every process", total * per, "on 2 cores: at most 2 x the wall"))
        return rows

    def _run(self) -> dict[str, tuple[float, str]]:
        what = {
            "physics": "10 ticks: DART, hydrodynamics, states out, the command in",
            "conductor": "the clock: grants, acks, the world/info and settings desks",
            "catabot run": "the launcher: progress lines, supervision",
        }
        return {name: (cpu, what.get(name, "")) for name, cpu in self.run_cpu_s.items()}


@dataclass
class Result:
    rate: float
    breakdown: Breakdown | None = None


def steps_per_s(env_id: str, seconds: float, *, breakdown: bool = False, **kwargs: Any) -> Result:
    """Env steps a wall-clock second over `seconds`, after a warm-up, one long episode."""
    env = gym.make(env_id, **(NEVER_THERE | kwargs))
    action = np.array(FORWARD, np.float32)
    try:
        env.reset(seed=SEED)
        for _ in range(WARMUP):
            env.step(action)
        probe = _Probe(env.unwrapped) if breakdown else None
        parts: list[Breakdown] = []
        steps, wall, part = 0, 0.0, (0, 0.0)
        while wall < seconds:
            started = time.perf_counter()
            _, _, terminated, truncated, _ = env.step(action)
            took = time.perf_counter() - started
            steps, wall, part = steps + 1, wall + took, (part[0] + 1, part[1] + took)
            if terminated or truncated:  # grounded on a shore: a new episode, not timed
                parts += [probe.finish(*part)] if probe else []
                env.reset()
                probe, part = (_Probe(env.unwrapped) if probe else None), (0, 0.0)
        parts += [probe.finish(*part)] if probe and part[0] else []
        result = Result(steps / wall, sum(parts[1:], parts[0]) if parts else None)
    finally:
        env.close()
    label = ", ".join(f"{k}={v}" for k, v in kwargs.items() if k != "max_steps") or "state only"
    print(f"  1 world ({label}): {result.rate:.0f} env steps/s", flush=True)
    return result


def vector_steps_per_s(
    env_id: str, n: int, seconds: float, *, asynchronous: bool, **kwargs: Any
) -> float:
    """Env steps a second summed over `n` worlds stepped together."""
    mode = "async" if asynchronous else "sync"
    # spawn: this process has opened Zenoh sessions, and a forked Zenoh runtime hangs
    vector = {"context": "spawn"} if asynchronous else {}
    envs = gym.make_vec(env_id, num_envs=n, vectorization_mode=mode, vector_kwargs=vector,
                        **(NEVER_THERE | kwargs))  # fmt: skip
    actions = np.tile(np.array(FORWARD, np.float32), (n, 1))
    try:
        envs.reset(seed=SEED)
        for _ in range(WARMUP):
            envs.step(actions)
        steps, started = 0, time.perf_counter()
        while time.perf_counter() - started < seconds:
            envs.step(actions)
            steps += 1
        rate = n * steps / (time.perf_counter() - started)
    finally:
        envs.close()
    label = ", ".join(f"{k}={v}" for k, v in kwargs.items() if k != "max_steps") or "state only"
    print(f"  {n} worlds, {mode} ({label}): {rate:.0f} env steps/s", flush=True)
    return rate


class _Probe:
    """CPU of the env's threads and of every process of its run, and the time the env's
    thread spends waiting in observe(), from now until `finish`."""

    def __init__(self, env: Any) -> None:
        assert isinstance(env, CataBotEnv)
        runner: Runner = env._runner
        live = runner.live
        assert live is not None and live.link is not None
        self.me = psutil.Process()
        self.main = threading.main_thread().native_id
        lockstep = [t for t in threading.enumerate() if t.name.startswith("lockstep-")]
        self.lockstep = lockstep[0].native_id if lockstep else None
        launcher = psutil.Process(live.run.proc.pid)
        self.run = {"catabot run": launcher, **{_name(p): p for p in launcher.children(True)}}
        self.waiting = 0.0
        original = runner.observe

        def timed() -> Any:
            started = time.perf_counter()
            try:
                return original()
            finally:
                self.waiting += time.perf_counter() - started

        runner.observe = timed  # type: ignore[method-assign]
        self.start = self._sample()

    def _sample(self) -> dict[str, float]:
        threads = {t.id: t.user_time + t.system_time for t in self.me.threads()}
        times = self.me.cpu_times()
        out = {
            "process": times.user + times.system,
            "main": threads.get(self.main or -1, 0.0),
            "lockstep": threads.get(self.lockstep or -1, 0.0),
        }
        for name, proc in self.run.items():
            t = proc.cpu_times()
            out[f"run:{name}"] = t.user + t.system
        return out

    def finish(self, steps: int, wall: float) -> Breakdown:
        end = self._sample()
        d = {k: end[k] - self.start[k] for k in end}
        run = {k[4:]: v for k, v in d.items() if k.startswith("run:")}
        return Breakdown(steps, wall, d["main"], d["lockstep"], d["process"], self.waiting, run)


def _name(proc: psutil.Process) -> str:
    cmd = proc.cmdline()
    module = cmd[2] if len(cmd) > 2 and cmd[1] == "-m" else proc.name()
    return {"catabot.run.conduct": "conductor"}.get(module, module.split(".")[-1])
