"""A free-running stack: `step(observation)` at a wall-clock rate, never holding the clock.

The observation is the newest `world/states` batch (tagged k-1: the state at the start of
tick k, as in the lockstep) and the newest sample of each sensor; the command goes out
free-running (tick -1) and is applied at the next tick boundary after it arrives
(DESIGN.md §4), so two runs differ: join the lockstep for determinism.
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable, Sequence
from typing import Any

import zenoh

from catabot.bus.clock import Stream
from catabot.bus.messages import BodyStates, End
from catabot.client.commands import Command
from catabot.client.info import SensorInfo, WorldInfo
from catabot.client.lockstep import Observation
from catabot.client.vessel import Vessel
from catabot.client.watch import Latest, Watch

log = logging.getLogger("catabot.client")
FIRST_STATE_S = 10.0  # a lockstep run may wait for its external participants first


class _Samples:
    """Every sample of the sensors since the last step, and the newest of each."""

    def __init__(self, watch: Watch, sensors: Sequence[SensorInfo]) -> None:
        self._lock = threading.Lock()
        self.newest: dict[str, Any] = {s.name: None for s in sensors}
        self.since: dict[str, list[Any]] = {s.name: [] for s in sensors}
        self.subs: list[zenoh.Subscriber] = []
        for s in sensors:
            stream = Stream(s.key, s.message, s.producer, None)
            self.subs.append(watch.subscribe(stream, self._taker(s.name)))

    def _taker(self, name: str) -> Callable[[Any], None]:
        def take(msg: Any) -> None:
            with self._lock:
                self.newest[name] = msg
                self.since[name].append(msg)

        return take

    def take(self) -> tuple[dict[str, Any], dict[str, list[Any]]]:
        with self._lock:
            since, self.since = self.since, {name: [] for name in self.since}
            return dict(self.newest), since


def run_free(
    watch: Watch,
    info: WorldInfo,
    vessel: Vessel,
    sensors: Sequence[SensorInfo],
    step: Callable[[Observation], Command | None],
    *,
    rate_hz: float,
    max_steps: int | None,
) -> End | None:
    if not rate_hz > 0:
        raise ValueError(f"rate_hz must be > 0 (got {rate_hz})")
    if unpaced(info):
        log.warning(unpaced(info))
    states = Latest(watch, Stream(info.states_key, BodyStates, info.states_producer, None,
                                  check=info.states_stream().check), "world state")  # fmt: skip
    samples = _Samples(watch, sensors)
    try:
        return _loop(watch, states, samples, vessel, step, 1.0 / rate_hz, max_steps)
    finally:  # a stack may run free again: leave no subscription behind
        for sub in [states.sub, *samples.subs]:
            watch.unsubscribe(sub)


def unpaced(info: WorldInfo) -> str:
    """Why a free stack would see little of a run not paced to the wall clock (a 10 Hz stack
    beside a run at 7.6x real time sent 34 commands in 30 simulated seconds), else ""."""
    if (info.scenario.get("clock") or {}).get("realtime_factor") is not None:
        return ""
    return (
        f"world {info.name!r} runs as fast as it can (no clock.realtime_factor): a free "
        "stack's rate is of the wall clock, so it sees the run only now and then; start "
        "the run with --realtime 1, or join the lockstep (run_lockstep) for every period"
    )


def _loop(
    watch: Watch,
    states: Latest,
    samples: _Samples,
    vessel: Vessel,
    step: Callable[[Observation], Command | None],
    period: float,
    max_steps: int | None,
) -> End | None:
    states.wait(FIRST_STATE_S)
    steps, next_at, told = 0, time.monotonic(), False
    while max_steps is None or steps < max_steps:
        if watch.end is not None:
            return watch.end
        ended = watch.ended()
        if ended is not None:
            raise ended
        bodies = states.message
        assert isinstance(bodies, BodyStates)
        newest, since = samples.take()
        state = bodies.row(vessel.info.row)
        obs = Observation(bodies.tick + 1, bodies.stamp_ns, state, bodies, newest, since)
        began = time.monotonic()
        command = step(obs)
        if command is not None:
            vessel.send(command)
        steps += 1
        told = told or _overran(time.monotonic() - began, period)
        next_at = max(next_at + period, time.monotonic())
        _sleep_until(watch, next_at)
    return None


def _overran(took_s: float, period_s: float) -> bool:
    """Said once: a step longer than its period (a 0.35 s step at 10 Hz ran at 2.9 Hz,
    unsaid)."""
    if took_s <= period_s:
        return False
    log.warning("a step took %.3g s, longer than its period (%.3g s, rate_hz %.3g): this "
                "stack steps at about %.3g Hz", took_s, period_s, 1 / period_s,
                1 / took_s)  # fmt: skip
    return True


def _sleep_until(watch: Watch, when: float) -> None:
    """Sleep until `when` (monotonic), waking early when the run ends."""
    with watch.changed:
        while time.monotonic() < when and watch.ended() is None:
            watch.changed.wait(min(when - time.monotonic(), 0.25))
