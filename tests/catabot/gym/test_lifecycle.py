"""An env's runs end with it, however its program ends; what reset takes."""

from __future__ import annotations

import json
import os
import socket
import subprocess
import sys
import textwrap
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np
import psutil
import pytest

import catabot.gym  # noqa: F401 - registers the envs
from catabot.gym import ActionError, link, process

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


def _episode(runs: Path, steps: int) -> Path:
    """One truncated episode's run folder, once its run has ended (env.close waits)."""
    env = gym.make("CataBot/Navigate-v0", max_steps=steps, recording="csv", runs_dir=str(runs))
    try:
        _, info = env.reset(seed=3)
        truncated = False
        while not truncated:
            _, _, terminated, truncated, _ = env.step(np.full(2, 0.4, np.float32))
            assert not terminated
    finally:
        env.close()
    assert isinstance(info["run_dir"], str)  # JSON as it is (a Path was not)
    run_dir = Path(info["run_dir"])
    ego = json.loads((run_dir / "scenario.json").read_text())["vessels"][0]
    goal = ego["task"]["goal"]  # the episode's goal is in its run folder
    assert (ego["id"], (goal["x_m"], goal["y_m"]), goal["radius_m"]) == ("ego", info["goal"], 3.0)
    return run_dir


def test_an_episode_ends_its_run_at_the_terminal_step_with_the_same_bytes(tmp_path: Path) -> None:
    """The env left the run at its end: run.json said "participant 'gym' left" and the
    recording stopped up to 20 ticks early or ran past the end, by timing."""
    first = _episode(tmp_path / "a", 12)
    record = json.loads((first / "log" / "run.json").read_text())
    reason = "ended by 'gym' after tick 129: episode truncated after 12 steps"
    assert (record["error"], record["reason"], record["ticks"]) == ("", reason, 130)
    state = (first / "vessel.ego.state.csv").read_text().splitlines()
    assert state[-1].split(",")[:2] == ["1300000000", "129"]  # the last observation's state
    second = _episode(tmp_path / "b", 12)
    names = sorted(p.name for p in first.glob("*.csv"))
    assert names == sorted(p.name for p in second.glob("*.csv")) and names
    assert [n for n in names if (first / n).read_bytes() != (second / n).read_bytes()] == []


def test_a_port_taken_before_the_run_binds_it_is_tried_again(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Another process took the port picked for the episode's run before the run bound it:
    reset failed ("Address already in use", a CI rehearsal); the runner starts it again,
    and the failed start's temporary folder goes (no error names its log)."""
    folders = []
    real_init = process.SimProcess.__init__

    def noted(run: process.SimProcess, *args: Any, **kwargs: Any) -> None:
        real_init(run, *args, **kwargs)
        folders.append(run.folder)

    monkeypatch.setattr(process.SimProcess, "__init__", noted)
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        ports = iter([taken.getsockname()[1]])
        real = process.free_port
        monkeypatch.setattr(process, "free_port", lambda: next(ports, 0) or real())
        env = gym.make("CataBot/Navigate-v0", max_steps=2)
        try:
            env.reset(seed=1)
            env.step(np.zeros(2, np.float32))
        finally:
            env.close()
    assert next(ports, None) is None  # the taken one was tried first
    assert len(folders) == 2 and not [f for f in folders if f.exists()]


def test_a_refused_first_reset_and_step_leave_the_env_usable_until_it_is_closed() -> None:
    """Gymnasium's passive checker (on by default) broke the env for good after a first
    reset that raised: every later step raised "cannot unpack non-iterable NoneType". And a
    reset after close() started a run that nothing ended: the program never exited."""
    env = gym.make("CataBot/Navigate-v0", max_steps=5)
    try:
        with pytest.raises(gym.error.Error, match="reset options"):
            env.reset(options={"goal": 1})
        env.reset(seed=1)
        with pytest.raises(ActionError, match="not finite"):
            env.step(np.array([np.nan, 0.0]))
        obs, *_ = env.step(np.zeros(2, np.float32))
        assert env.observation_space.contains(obs)
    finally:
        env.close()
    before = set(psutil.Process().children(recursive=True))
    with pytest.raises(gym.error.ClosedEnvironmentError, match="make a new one"):
        env.reset(seed=1)
    with pytest.raises(gym.error.ClosedEnvironmentError):
        env.step(np.zeros(2, np.float32))
    assert set(psutil.Process().children(recursive=True)) <= before  # no run started


def test_a_forked_env_is_refused_before_any_run_starts(monkeypatch: pytest.MonkeyPatch) -> None:
    """A vector env's worker forked after Zenoh opened: refused only once its run had
    started, which left that run's folder behind and said "catabot run (still running...)"."""
    monkeypatch.setitem(link._zenoh, "forked", True)  # as os.register_at_fork sets it
    env = gym.make("CataBot/Navigate-v0", max_steps=5)
    before = set(psutil.Process().children(recursive=True))
    try:
        with pytest.raises(link.LinkError, match="context='spawn'") as refused:
            env.reset(seed=1)
        assert "catabot run" not in str(refused.value)
        assert set(psutil.Process().children(recursive=True)) <= before
    finally:
        env.close()
