"""Rates as whole numbers of ticks (DESIGN.md §4): every rate a scenario sets is checked here
once, when the scenario is loaded, and each consumer turns its rate into ticks the same way."""

from __future__ import annotations

import math

from catabot.bus.clock import NS_PER_S, ClockError, period_in_ticks
from catabot.config.base import ScenarioError
from catabot.config.scenario import Scenario

MAX_PERIOD_NS = 2**63 - 1  # the clock counts in signed 64-bit nanoseconds (msgpack, numpy)


def check_rates(scenario: Scenario) -> None:
    """Refuse sensor and guidance rates that are not a whole number of ticks (DESIGN.md §4),
    sensors too big to sample in memory, and parameters that do not go with their rate."""
    for v_index, vessel in enumerate(scenario.vessels):
        for s_index, sensor in enumerate(vessel.sensors):
            where = f"vessels.{v_index}.sensors.{s_index}.rate_hz ({vessel.id}/{sensor.name})"
            rate_in_ticks(sensor.rate_hz, scenario.dt_ns, where=where)
            params = sensor.typed_params()
            problem = params.memory_problem() or params.rate_problem(sensor.rate_hz)
            if problem:
                at = f"vessels.{v_index}.sensors.{s_index}.params ({vessel.id}/{sensor.name})"
                raise ScenarioError(f"{at}: {problem}")
        if vessel.controller is not None:
            where = f"vessels.{v_index}.controller.rate_hz ({vessel.id})"
            rate_in_ticks(vessel.controller.rate_hz, scenario.dt_ns, where=where)
    if scenario.traffic.count:
        guidance_period_ticks(scenario)
    if scenario.ros is not None and scenario.ros.clock_hz is not None:
        rate_in_ticks(scenario.ros.clock_hz, scenario.dt_ns, where="ros.clock_hz")
    if scenario.recording.traffic_rate_hz is not None and (
        scenario.traffic.count or scenario.buoys
    ):
        traffic_record_period(scenario)
    if scenario.recording.dataset_rate_hz is not None:
        dataset_period(scenario)
    try:
        scenario.ticks  # noqa: B018 - validates duration against dt
    except ClockError as exc:
        raise ScenarioError(f"duration_s: {exc}") from None
    if scenario.duration_ns % scenario.dt_ns:  # cut to whole ticks, unsaid: a run looked short
        dt_s, whole = scenario.dt_ns / NS_PER_S, scenario.ticks * scenario.dt_ns / NS_PER_S
        raise ScenarioError(f"duration_s: {scenario.duration_s:g} s is not a whole number of "
                            f"ticks of {dt_s:g} s (the run would end at {whole:g} s)")  # fmt: skip


def rate_in_ticks(rate_hz: float, dt_ns: int, *, where: str) -> int:
    """The period of a rate in ticks; ScenarioError naming `where` unless it is whole, or
    too long for the clock's nanosecond integers (1e-300 Hz overflowed to a traceback)."""
    if not NS_PER_S / rate_hz <= MAX_PERIOD_NS:
        raise ScenarioError(f"{where}: {rate_hz:g} Hz is too slow: one sample in "
                            f"{1 / rate_hz:.3g} s, past the clock's {MAX_PERIOD_NS / NS_PER_S:.3g} "
                            "s of nanoseconds")  # fmt: skip
    try:  # first, so that e.g. 30 Hz at 10 ms names the allowed rates
        ticks = period_in_ticks(round(NS_PER_S / rate_hz), dt_ns, what=where)
    except ClockError as exc:
        raise ScenarioError(f"{exc}; {nearest_rates(rate_hz, dt_ns)}") from None
    exact = NS_PER_S / rate_hz
    if not math.isclose(exact, round(exact), rel_tol=1e-12, abs_tol=1e-6):
        raise ScenarioError(f"{where}: {rate_hz} Hz is not a whole number of ns")
    return ticks


def guidance_period_ticks(scenario: Scenario) -> int:
    """Ticks between two rounds of traffic set-points (`traffic.guidance_hz`)."""
    return rate_in_ticks(scenario.traffic.guidance_hz, scenario.dt_ns, where="traffic.guidance_hz")


def traffic_record_period(scenario: Scenario) -> int:
    """Ticks between two recorded states of the traffic and the buoys (1: every tick)."""
    rate = scenario.recording.traffic_rate_hz
    if rate is None:
        return 1
    where = "recording.traffic_rate_hz (null records every tick)"
    return rate_in_ticks(rate, scenario.dt_ns, where=where)


def nearest_rates(rate_hz: float, dt_ns: int) -> str:
    """The whole-tick rates either side of one that is not (a user asking 3 Hz at 100 Hz
    ticks wants to hear 3.03 or 2.94 Hz, not to work it out)."""
    tick_hz, every = NS_PER_S / dt_ns, NS_PER_S / dt_ns / rate_hz
    if every < 1.0:
        return f"the fastest is {tick_hz:g} Hz (every tick)"
    low, high = math.floor(every), math.ceil(every)
    slow, fast = tick_hz / high, tick_hz / low
    return f"the nearest are {fast:.4g} Hz (every {low} ticks) and {slow:.4g} Hz (every {high})"


def dataset_period(scenario: Scenario) -> int:
    """Ticks between two saved camera frames (`recording.dataset_rate_hz`): a whole number
    of every camera's periods, so the frames kept are evenly spaced. A 4 Hz dataset of a 5 Hz
    camera had kept frames 0.4 and 0.2 s apart in turn, and 10 Hz had kept 5 Hz, unsaid."""
    rate, where = scenario.recording.dataset_rate_hz, "recording.dataset_rate_hz"
    assert rate is not None
    every = rate_in_ticks(rate, scenario.dt_ns, where=where)
    cameras = [(f"{v.id}/{s.name}", s.rate_hz) for v in scenario.vessels for s in v.sensors
               if s.type == "camera"]  # fmt: skip
    periods = {name: rate_in_ticks(hz, scenario.dt_ns, where=name) for name, hz in cameras}
    unfit = [name for name, p in periods.items() if every % p]
    if unfit and scenario.recording.dataset:
        whole = math.lcm(*periods.values())
        fits = ", ".join(f"{NS_PER_S / scenario.dt_ns / (whole * n):.4g}" for n in range(1, 5))
        hz = " or ".join(f"{name}'s {dict(cameras)[name]:g} Hz" for name in unfit)
        raise ScenarioError(f"{where}: {rate:g} Hz is not {hz} divided by a whole number: the "
                            f"dataset keeps whole camera frames, evenly spaced; rates that fit: "
                            f"{fits} Hz, ...")  # fmt: skip
    return every
