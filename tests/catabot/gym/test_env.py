"""The environment against real runs: Gymnasium's checker, episodes reproducible from the
seed, the usual errors after an episode ends and for bad actions, nothing left running."""

from __future__ import annotations

import os
import re
import shutil
import time
from collections.abc import Iterator
from pathlib import Path

import gymnasium as gym
import numpy as np
import psutil
import pytest
from gymnasium.error import ResetNeeded
from gymnasium.utils.env_checker import check_env, check_reset_return_type, check_space_limit
from gymnasium.utils.passive_env_checker import (
    check_action_space,
    check_observation_space,
    env_reset_passive_checker,
    env_step_passive_checker,
)

import catabot.gym  # noqa: F401 - registers the envs
from catabot.gym import ActionError, CataBotEnv
from catabot.gym.link import LinkError

pytestmark = pytest.mark.timeout(240)
FORWARD = np.array([0.6, 0.5], np.float32)


@pytest.fixture(scope="module")
def env() -> Iterator[gym.Env]:
    e = gym.make("CataBot/Navigate-v0", max_steps=40)
    yield e
    e.close()


def run_processes() -> set[int]:
    """This test process's descendants that are CataBot runs or services."""
    return {p.pid for p in psutil.Process().children(recursive=True) if p.is_running()}


def test_gymnasium_env_checker_passes(env: gym.Env) -> None:
    """The whole checker resets a dozen times (a `catabot run` each: 35 s of CI's 15
    minutes), so CI runs its space, reset and step checks; `CATABOT_SLOW=1` the whole of it
    (the seed and step determinism it adds are also this file's own tests)."""
    if os.environ.get("CATABOT_SLOW"):
        check_env(env.unwrapped)
        return
    plain = env.unwrapped
    check_action_space(plain.action_space)
    check_observation_space(plain.observation_space)
    for space, kind in ((plain.action_space, "action"), (plain.observation_space, "observation")):
        check_space_limit(space, kind)
    check_reset_return_type(plain)
    env_reset_passive_checker(plain, seed=3)
    env_step_passive_checker(plain, plain.action_space.sample())


def test_the_same_seed_gives_the_same_first_observations_and_steps(env: gym.Env) -> None:
    def episode(seed: int) -> list[np.ndarray]:
        obs, _ = env.reset(seed=seed)
        seen = [obs["state"]]
        for _ in range(4):
            obs, reward, *_ = env.step(FORWARD)
            seen += [obs["state"], np.array([reward])]
        return seen

    first, again, other = episode(7), episode(7), episode(8)
    for a, b in zip(first, again, strict=True):
        np.testing.assert_array_equal(a, b)
    assert not np.array_equal(first[0], other[0])
    assert first[1][7] > first[0][7]  # it got going: surge grew


def test_bad_actions_are_clear_errors_and_the_episode_goes_on(env: gym.Env) -> None:
    env.reset(seed=1)
    with pytest.raises(ActionError, match="not finite"):
        env.step(np.array([np.nan, 0.0]))
    with pytest.raises(ActionError, match=r"shape \(3,\); this env takes \(2,\)"):
        env.step(np.zeros(3))
    with pytest.raises(ActionError, match=r"outside \[-1, 1\]"):
        env.step(np.array([1.5, 0.0]))
    for bad in ("full ahead", np.array([True, False]), np.array([1j, 0])):
        with pytest.raises(ActionError, match="not an array of real numbers"):
            env.step(bad)
    obs, *_ = env.step(FORWARD)
    assert env.observation_space.contains(obs)


def test_a_step_after_the_episode_ends_raises_reset_needed() -> None:
    env = gym.make("CataBot/Navigate-v0", max_steps=2, goal_radius_m=100.0)
    try:
        with pytest.raises(ResetNeeded):
            env.step(FORWARD)  # before any reset (Gymnasium's OrderEnforcing)
        env.reset(seed=2)
        _, reward, terminated, truncated, info = env.step(FORWARD)
        assert terminated and not truncated and info["reached"] and reward > 90
        with pytest.raises(ResetNeeded, match="after the episode ended"):
            env.step(FORWARD)
    finally:
        env.close()


def test_the_episode_is_truncated_at_max_steps(env: gym.Env) -> None:
    env.reset(seed=5)
    steps = [env.step(FORWARD)[2:4] for _ in range(40)]
    assert steps[-1] == (False, True) and all(s == (False, False) for s in steps[:-1])
    with pytest.raises(ResetNeeded):
        env.step(FORWARD)


def test_prelaunched_episodes_are_the_episodes_and_close_leaves_no_process(
    env: gym.Env,
) -> None:
    """With prelaunch the next seedless episode's run starts early: the episodes are the
    same as without, and close() ends both runs, every process of each."""
    env.reset(seed=3)
    expected, _ = env.reset()  # the second episode after seed 3, started at the reset
    before = run_processes()
    early = CataBotEnv(max_steps=5, prelaunch=True)
    early.reset(seed=3)
    early.step(FORWARD)
    time.sleep(1.0)  # the next episode's run starts meanwhile
    obs, _ = early.reset()
    np.testing.assert_array_equal(obs["state"], expected["state"])
    started = run_processes() - before
    names = {" ".join(psutil.Process(p).cmdline()[1:3]) for p in started}
    assert {"-m catabot", "-m catabot.run.conduct", "-m services.physics"} <= names, names
    early.close()
    left = [p for p in started if psutil.pid_exists(p) and psutil.Process(p).status() != "zombie"]
    assert not left, [psutil.Process(p).cmdline() for p in left]
    early.close()  # twice is fine


def test_a_run_that_fails_mid_episode_is_a_clear_error_and_reset_recovers(env: gym.Env) -> None:
    env.reset(seed=4)
    env.step(FORWARD)
    live = env.unwrapped._runner.live  # type: ignore[attr-defined]
    launcher = psutil.Process(live.run.proc.pid)
    (physics,) = [p for p in launcher.children(recursive=True) if "services.physics" in p.cmdline()]
    physics.kill()
    with pytest.raises(LinkError, match="physics") as failed:
        for _ in range(50):
            env.step(FORWARD)
    with pytest.raises(ResetNeeded):
        env.step(FORWARD)
    obs, info = env.reset(seed=4)
    assert env.observation_space.contains(obs)
    assert info["endpoint"].startswith("tcp/127.0.0.1:")  # for `catabot view --connect`
    assert info["collision"] is None and info["reached"] is False  # step's outcome keys too
    said = str(failed.value)  # the run's cause, not the start's lines ("waiting for gym ...")
    assert "run failed: participant 'physics'" in said and "waiting for" not in said, said
    log = Path(re.findall(r"log (/\S+/run\.log), kept", said)[0])
    assert log.is_file() and "physics" in log.read_text()  # named, and still there to read
    shutil.rmtree(log.parent)


def test_max_steps_above_the_default_is_not_cut_by_a_time_limit() -> None:
    """Registered with max_episode_steps=600, a TimeLimit ended max_steps=700 at 600. No
    TimeLimit, but the spec gives the horizon (it said None: RL libraries read it there)."""
    env = gym.make("CataBot/Navigate-v0", max_steps=700)
    try:
        assert not isinstance(env, gym.wrappers.TimeLimit)
        assert env.spec is not None and env.spec.max_episode_steps == 700
        assert env.unwrapped.options.max_steps == 700  # type: ignore[attr-defined]
    finally:
        env.close()
    default = gym.make("CataBot/StationKeep-v0")
    assert default.spec is not None and default.spec.max_episode_steps == 600
    default.close()
