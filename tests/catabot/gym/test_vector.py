"""Several worlds side by side: each env its own run, port and key prefix, stepped by
Gymnasium's vector envs; the same seeds give the same worlds as single envs do."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

import catabot.gym  # noqa: F401 - registers the envs

pytestmark = pytest.mark.timeout(240)
ENV = "CataBot/Navigate-v0"
FORWARD = np.array([0.6, 0.5], np.float32)


def test_async_worlds_step_side_by_side_and_reset_by_themselves() -> None:
    envs = gym.make_vec(ENV, num_envs=2, vectorization_mode="async", max_steps=3,
                        vector_kwargs={"context": "spawn"})  # fmt: skip
    try:
        obs, _ = envs.reset(seed=[11, 12])
        assert obs["state"].shape == (2, 10)
        assert not np.array_equal(obs["state"][0], obs["state"][1])  # two episodes
        for _ in range(3):
            obs, rewards, terminated, truncated, _ = envs.step(np.tile(FORWARD, (2, 1)))
        assert truncated.all() and not terminated.any() and rewards.shape == (2,)
        obs, *_ = envs.step(np.tile(FORWARD, (2, 1)))  # the next-step autoreset: new episodes
        assert obs["state"].shape == (2, 10)
    finally:
        envs.close()


def test_a_world_of_a_vector_env_is_the_single_env_of_its_seed() -> None:
    single = gym.make(ENV, max_steps=3)
    try:
        first, _ = single.reset(seed=12)
        stepped, *_ = single.step(FORWARD)
    finally:
        single.close()
    envs = gym.make_vec(ENV, num_envs=2, vectorization_mode="sync", max_steps=3)
    try:
        obs, _ = envs.reset(seed=[11, 12])
        np.testing.assert_array_equal(obs["state"][1], first["state"])
        obs, *_ = envs.step(np.tile(FORWARD, (2, 1)))
        np.testing.assert_array_equal(obs["state"][1], stepped["state"])
    finally:
        envs.close()
