"""Services run as batch work: the policy is set, inherited by later threads, and refusable."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

from catabot.bus.scheduling import SchedulingError, requested_policy

LINUX = pytest.mark.skipif(not hasattr(os, "SCHED_BATCH"), reason="SCHED_BATCH is Linux-only")
PROBE = """
import os, threading, time
early = threading.Thread(target=time.sleep, args=(2,), daemon=True)  # before the call
early.start()
from catabot.bus.scheduling import batch_scheduling
print(batch_scheduling(), os.sched_getscheduler(early.native_id) == os.SCHED_BATCH, end=" ")
seen = []
thread = threading.Thread(target=lambda: seen.append(os.sched_getscheduler(0) == os.SCHED_BATCH))
thread.start(); thread.join()
print(seen[0])
"""


def _probe(sched: str | None) -> str:
    env = {k: v for k, v in os.environ.items() if k != "CATABOT_SCHED"}
    if sched is not None:
        env["CATABOT_SCHED"] = sched
    done = subprocess.run(
        [sys.executable, "-c", PROBE], capture_output=True, text=True, env=env, timeout=60
    )
    assert done.returncode == 0, done.stderr
    return done.stdout.strip()


@LINUX
def test_batch_is_the_default_for_every_thread_and_later_ones_inherit_it() -> None:
    assert _probe(None) == "True True True"


@LINUX
def test_normal_keeps_the_default_policy() -> None:
    assert _probe("normal") == "False False False"


@pytest.mark.parametrize("value", ["fast", "", "realtime"])
def test_an_unknown_policy_is_refused_naming_the_variable(
    value: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("CATABOT_SCHED", value)
    with pytest.raises(SchedulingError, match=r"CATABOT_SCHED=.*use one of batch, normal"):
        requested_policy()


def test_the_variable_is_read_case_blind(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("CATABOT_SCHED", " Normal ")
    assert requested_policy() == "normal"
