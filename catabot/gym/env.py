"""`CataBotEnv`: a Gymnasium environment over a real lockstep run of the simulator.

reset(seed) draws the episode (catabot.gym.episode), starts its run (catabot.gym.process)
and takes the ego's controller seat in the lockstep (catabot.gym.link); step(action) sends
the command of this control period and returns the observation of the next one, exactly
one control period later in simulated time, on every run alike. The episode's first
observation is taken one control period after t = 0, with a zero command in force, so that
every observed sensor (any rate at or above the control rate's period) has a sample.
"""

from __future__ import annotations

import dataclasses
import itertools
import os
import threading
import weakref
from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium.envs.registration import EnvSpec
from gymnasium.error import ResetNeeded

from catabot.client import Thrust, Twist
from catabot.errors import CataBotError
from catabot.gym.episode import Draw, Episode
from catabot.gym.judge import Judge
from catabot.gym.link import Command, Frame, LinkError
from catabot.gym.observation import Obs, Observer, observation_space
from catabot.gym.options import env_options
from catabot.gym.runner import Runner
from catabot.world.geo import EnuFrame

_INSTANCES = itertools.count()
SEED_HIGH = 2**63 - 1


class ActionError(CataBotError, ValueError):
    """An action the env cannot send: wrong shape, not finite, or outside the action space."""


class CataBotEnv(gym.Env[Obs, np.ndarray]):
    metadata: dict[str, Any] = {"render_modes": []}
    _spec: EnvSpec | None = None

    def __init__(self, render_mode: str | None = None, **kwargs: Any) -> None:
        if render_mode is not None:
            raise gym.error.Error(f"CataBot envs render nothing here (got {render_mode!r}); "
                                  "watch an episode's run with `catabot view --connect "
                                  "ENDPOINT` (reset's info['endpoint'])")  # fmt: skip
        self.options = o = env_options(**kwargs)
        self._draw = Draw(o)
        base = (o.world or self._draw.base.name)[:40]
        self.world = f"{base}-gym{os.getpid()}x{next(_INSTANCES)}"
        n = len(self._draw.model.thrusters) if o.action == "thrust" else 2
        self.action_space = gym.spaces.Box(-1.0, 1.0, (n,), np.float32)
        self.observation_space = observation_space(o)  # type: ignore[assignment]
        self._runner = Runner(o, self._draw, self.world)
        # An env never closed (a script's end, a dropped env in a notebook) left its run's
        # processes behind, and Zenoh's callback threads held the interpreter's exit: its
        # runs end when it is collected, and at exit before those threads are joined.
        self._closer = weakref.finalize(self, self._runner.close)
        threading._register_atexit(self._closer)  # type: ignore[attr-defined]
        self._origin = EnuFrame(**self._draw.base.origin.model_dump())
        self._episode: Episode | None = None
        self._judge: Judge | None = None
        self._observer: Observer | None = None
        self._steps = 0
        self._upcoming: int | None = None  # the next seedless episode's seed (prelaunch)
        self._over = True  # no episode to step: reset first

    @property
    def spec(self) -> EnvSpec | None:
        return self._spec

    @spec.setter
    def spec(self, value: EnvSpec | None) -> None:
        """`gym.make` sets a spec without a horizon (the env truncates itself, no TimeLimit):
        RL libraries that read `spec.max_episode_steps` found None; it is `max_steps`."""
        if value is not None and value.max_episode_steps is None:
            value = dataclasses.replace(value, max_episode_steps=self.options.max_steps)
        self._spec = value

    # -- Gymnasium's API ---------------------------------------------------------------

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[Obs, dict[str, Any]]:
        if options:
            raise gym.error.Error(
                f"reset options: this env takes none (got {sorted(options)}); its episodes "
                "are set by gymnasium.make's keywords (catabot.gym.options.EnvOptions)"
            )
        self._open()
        super().reset(seed=seed)
        if seed is not None or self._upcoming is None:
            episode_seed = int(self.np_random.integers(0, SEED_HIGH))
        else:  # drawn at the previous reset, its run started then
            episode_seed = self._upcoming
        prelaunch = self.options.prelaunch
        self._upcoming = int(self.np_random.integers(0, SEED_HIGH)) if prelaunch else None
        self._over = True
        live = self._runner.start(episode_seed, self._upcoming)
        self._episode, world = live.episode, live.world
        self._judge = Judge(world, self._draw.vessel, self.options)
        names: dict[str, str] = dict(
            zip(self.options.sensors, self._draw.sensor_names(), strict=True)
        )
        self._observer = Observer(self.options, world.body(self._draw.vessel).row, names,
                                  self._origin)  # fmt: skip
        self._observer.goal = self._episode.goal
        self._runner.act(self._command(np.zeros(self.action_space.shape or (0,))))
        frame = self._runner.observe()
        self._judge.start(self._episode.goal, frame.bodies)
        self._steps, self._over = 0, False
        run_dir = str(live.run.run_dir()) if self.options.runs_dir is not None else None
        where = {"run_dir": run_dir, "endpoint": live.run.endpoint}  # `catabot view --connect`
        return self._observer(frame), self._info(frame) | self._judge.flags(frame.bodies) | where

    def step(self, action: Any) -> tuple[Obs, float, bool, bool, dict[str, Any]]:
        self._open()
        if self._over or self._judge is None or self._observer is None:
            raise ResetNeeded(
                "Cannot call env.step() before calling env.reset() or after the episode "
                "ended (terminated or truncated): its run is over, call env.reset()"
            )
        a = self._checked(action)
        try:
            self._runner.act(self._command(a))
            frame = self._runner.observe()
        except (LinkError, CataBotError):
            self._over = True
            self._runner.end()
            raise
        verdict = self._judge(frame.bodies, a)
        self._steps += 1
        truncated = not verdict.terminated and self._steps >= self.options.max_steps
        info = self._info(frame) | {
            "reached": verdict.reached,
            "collision": verdict.collision,
            "grounded": verdict.grounded,
        }
        if verdict.terminated or truncated:
            self._over = True
            self._runner.end(verdict.why(self._steps))
        return self._observer(frame), verdict.reward, verdict.terminated, truncated, info

    def close(self) -> None:
        self._over = True
        self._closer()
        super().close()

    # -- helpers ----------------------------------------------------------------------

    def _open(self) -> None:
        """A reset after close() started a run that nothing would end: its processes and
        Zenoh's threads held the interpreter's exit for ever."""
        if not self._closer.alive:
            raise gym.error.ClosedEnvironmentError(
                "this env is closed (its runs ended): make a new one with gymnasium.make"
            )

    def _checked(self, action: Any) -> np.ndarray:
        space = self.action_space
        try:
            given = np.asarray(action)
            if given.dtype.kind in "bc":  # True as full thrust, 1j as 0: silently not meant
                raise TypeError
            a = given.astype(np.float64)
        except (TypeError, ValueError):
            raise ActionError(f"action {action!r} is not an array of real numbers") from None
        if a.shape != space.shape:
            raise ActionError(f"action has shape {a.shape}; this env takes {space.shape} "
                              f"({self._action_meaning()})")  # fmt: skip
        if not np.isfinite(a).all():
            raise ActionError(f"action {a.tolist()} is not finite (NaN or infinity)")
        if np.any(np.abs(a) > 1.0 + 1e-6):
            raise ActionError(f"action {a.tolist()} is outside [-1, 1] ({self._action_meaning()}; "
                              "clip it, e.g. gymnasium.wrappers.ClipAction)")  # fmt: skip
        return np.clip(a, -1.0, 1.0)

    def _action_meaning(self) -> str:
        o = self.options
        if o.action == "thrust":
            return f"one thrust per thruster of the {self._draw.vessel!r} vessel, each in [-1, 1]"
        return (f"surge and yaw rate in [-1, 1], scaled to {o.max_surge_mps:g} m/s and "
                f"{o.max_yaw_rate_radps:g} rad/s")  # fmt: skip

    def _command(self, a: np.ndarray) -> Command:
        values = a.tolist()
        if self.options.action == "thrust":
            return Thrust(values)
        o = self.options
        return Twist(values[0] * o.max_surge_mps, values[1] * o.max_yaw_rate_radps)

    def _info(self, frame: Frame) -> dict[str, Any]:
        assert self._episode is not None and self._judge is not None
        return {
            "tick": frame.tick,
            "time_s": frame.stamp_ns * 1e-9,
            "distance_m": self._judge.distance(frame.bodies),
            "episode_seed": self._episode.seed,
            "goal": (self._episode.goal.x_m, self._episode.goal.y_m),
        }
