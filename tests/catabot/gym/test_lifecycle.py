"""An env's runs end with it, however its program ends; what reset takes."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap

import gymnasium as gym
import numpy as np
import psutil
import pytest

import catabot.gym  # noqa: F401 - registers the envs

pytestmark = pytest.mark.timeout(180)

NEVER_CLOSED = textwrap.dedent("""
    import gymnasium as gym, numpy as np, catabot.gym
    env = gym.make("CataBot/Navigate-v0", max_steps=20)
    env.reset(seed=1)
    for _ in range(3):
        env.step(np.zeros(2, np.float32))
    print("world", env.unwrapped.world, flush=True)
""")


def _shm_files() -> int:
    fds = [os.path.join("/proc/self/fd", f) for f in os.listdir("/proc/self/fd")]
    return sum("zenoh" in os.readlink(f) for f in fds if os.path.exists(f))


def test_a_script_that_never_closes_its_env_exits_and_leaves_no_run() -> None:
    """It hung at exit (Zenoh's callback threads were joined first) with its run alive."""
    done = subprocess.run([sys.executable, "-c", NEVER_CLOSED], capture_output=True,
                          text=True, timeout=120)  # fmt: skip
    assert done.returncode == 0, done.stderr
    world = done.stdout.split()[-1]
    left = [
        p for p in psutil.process_iter(["cmdline"]) if world in " ".join(p.info["cmdline"] or [])
    ]
    assert not left, [p.info["cmdline"][:3] for p in left]


def test_episodes_map_no_shared_memory_and_reset_takes_no_options() -> None:
    """Each episode's run left ≈1.3 mapped /dev/shm files in the env's process; and a reset
    option (none is read) was silently ignored."""
    before = _shm_files()  # other tests' sessions in this worker may hold some
    env = gym.make("CataBot/Navigate-v0", max_steps=3)
    try:
        for seed in range(3):
            env.reset(seed=seed)
            env.step(np.zeros(2, np.float32))
        assert _shm_files() <= before
        with pytest.raises(gym.error.Error, match=r"reset options: this env takes none \(got"):
            env.reset(options={"bogus": 1})
    finally:
        env.close()
