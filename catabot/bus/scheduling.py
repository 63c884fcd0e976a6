"""How the operating system schedules a stepping service: as batch work (Linux SCHED_BATCH).

Why: with five processes on two cores, every sample that woke a process used to preempt the
one computing (about 25,000 context switches a second with 100 traffic boats), and each
switch evicted the caches of the process that was working. A stepping service is
throughput work, never interactive: SCHED_BATCH keeps its fair share of CPU but does not
preempt on wake-up. Measured on the 2-core machine (`python -m benchmarks.table2`, 5 s):
100 boats 4.6 -> 5.1 real-time factor, 0 boats 10.5 -> 13.9; every service used less CPU a
tick. Paced runs (`clock.realtime_factor`) leave the cores mostly idle, so the policy
changes nothing there. `CATABOT_SCHED=normal` keeps the default policy.
"""

from __future__ import annotations

import logging
import os

from catabot.errors import CataBotError

log = logging.getLogger("catabot.bus.scheduling")
POLICIES = ("batch", "normal")


class SchedulingError(CataBotError, ValueError):
    """`CATABOT_SCHED` names no policy CataBot knows."""


def requested_policy() -> str:
    """`CATABOT_SCHED` (default batch); SchedulingError for any other value."""
    policy = os.environ.get("CATABOT_SCHED", "batch").strip().lower()
    if policy not in POLICIES:
        raise SchedulingError(
            f"CATABOT_SCHED={os.environ['CATABOT_SCHED']!r}: use one of {', '.join(POLICIES)}"
        )
    return policy


def batch_scheduling() -> bool:
    """Put every thread of this process (NumPy's idle OpenBLAS workers too) under
    SCHED_BATCH; threads started afterwards (Zenoh's) inherit it, so call this before
    opening the session. True if the policy is now batch. Where the platform has no
    SCHED_BATCH (macOS, Windows) or refuses it, the run goes on under the default."""
    if requested_policy() != "batch" or not hasattr(os, "SCHED_BATCH"):
        return False
    try:
        for thread in _threads():
            os.sched_setscheduler(thread, os.SCHED_BATCH, os.sched_param(0))
    except OSError as exc:
        log.warning("SCHED_BATCH refused (%s); running under the default policy", exc)
        return False
    return True


def _threads() -> list[int]:
    """This process's thread ids (Linux); [0], the calling thread, where /proc is absent."""
    try:
        return [int(t) for t in os.listdir("/proc/self/task")]
    except OSError:
        return [0]
