"""What the plots show, read from a run folder once: arrays over simulated time.

Everything comes through `catabot.run.recorded` (run.mcap and metrics.json), so the plots
show exactly what was recorded; derived series (speed, heading, closest approach) are
computed array-wide here.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from catabot.config.vessel import Thruster
from catabot.run.recorded import RecordedRun, StateTrack
from catabot.world import rotations

F64 = NDArray[np.float64]


@dataclass
class Series:
    """Sample times (s) and values (T, k) of one quantity of one owner, with column names."""

    t: F64
    values: F64
    names: tuple[str, ...]


@dataclass
class RunSeries:
    run: RecordedRun
    states: StateTrack
    t: F64  # the states' stamps, s
    own: list[str]  # scenario vessels
    speed: dict[str, F64] = field(default_factory=dict)
    heading: dict[str, F64] = field(default_factory=dict)
    closest: F64 = field(default_factory=lambda: np.empty(0))
    pairs: dict[str, F64] = field(default_factory=dict)  # "a-b": two own vessels' distance
    thrust: dict[str, Series] = field(default_factory=dict)
    setpoint: dict[str, Series] = field(default_factory=dict)
    imu: dict[str, Series] = field(default_factory=dict)
    lidar: dict[str, Series] = field(default_factory=dict)
    metrics: dict[str, Any] | None = None


def read(run: RecordedRun, *, full: bool = True) -> RunSeries:
    """`full`: the commands and sensors too (one run's plots); without, the states alone
    (runs compared)."""
    states = run.states()
    own = [v.id for v in run.world.scenario.vessels]
    out = RunSeries(run, states, states.stamp_ns / 1e9, own, metrics=run.metrics())
    rows = [run.world.body(v).row for v in own]
    yaw = rotations.yaw_of_quaternions(states.orientation[:, rows].reshape(-1, 4))
    yaw = yaw.reshape(len(states), len(rows))
    for k, (vid, row) in enumerate(zip(own, rows, strict=True)):
        out.speed[vid] = np.hypot(states.twist[:, row, 0], states.twist[:, row, 1])
        out.heading[vid] = (90.0 - np.degrees(yaw[:, k])) % 360.0
    out.closest = closest_approach(states.position[:, : len(run.world.vessels), :2], rows)
    out.pairs = own_pairs(states.position[:, rows, :2], own)
    if full:
        _commands(run, out)
        _sensors(run, out)
    return out


def own_pairs(xy: F64, own: list[str], most: int = 6) -> dict[str, F64]:
    """Each pair of the scenario's own vessels (a fleet of up to `most`): their distance over
    time, beside the closest approach of any two, which flattens after one pile-up."""
    if not 2 <= len(own) <= most:
        return {}
    i, j = np.triu_indices(len(own), k=1)
    gaps = np.linalg.norm(xy[:, i] - xy[:, j], axis=-1)  # (T, pairs)
    return {f"{own[a]}-{own[b]}": gaps[:, k] for k, (a, b) in enumerate(zip(i, j, strict=True))}


def closest_approach(xy: F64, own: list[int]) -> F64:
    """(T,) smallest distance from one of the `own` rows (the scenario's vessels) to any
    other vessel at each tick (inf without a pair): as metrics.json's closest approach,
    which leaves out traffic boat against traffic boat (the plot's curve had them)."""
    if xy.shape[1] < 2 or not own:
        return np.full(len(xy), np.inf)
    out = np.empty(len(xy))
    for start in range(0, len(xy), 256):  # bounded memory: (256, S, N) distances at a time
        block = xy[start : start + 256]
        gap = np.linalg.norm(block[:, own, None] - block[:, None], axis=-1)
        gap[:, np.arange(len(own)), own] = np.inf
        out[start : start + 256] = gap.min(axis=(1, 2))
    return out


def _commands(run: RecordedRun, out: RunSeries) -> None:
    """Thrust: every recorded thrust command, scripted or sent (a folder recorded before
    the recorder wrote the script's steps: the script's steps); twist set-points."""
    for vid in out.own:
        body = run.world.body(vid)
        steps: list[tuple[float, Sequence[float]]] = [
            (s.t_s, s.thrust) for s in body.script if s.thrust is not None
        ]
        sent: list[tuple[float, Sequence[float]]] = [
            (stamp_ns / 1e9, c.thrust) for stamp_ns, c in run.thrust(vid)
        ]
        both = sorted(sent or steps, key=lambda p: p[0])
        if both:
            n = max(len(v) for _, v in both)
            values = np.array([[*v, *[np.nan] * (n - len(v))] for _, v in both])
            names = _thruster_names(body.model.thrusters, n)
            out.thrust[vid] = Series(np.array([t for t, _ in both]), values, names)
        end = run.world.scenario.duration_s  # a step after a shortened run's end: not drawn
        scripted = [(s.t_s, (s.twist.surge_mps, s.twist.yaw_rate_radps))
                    for s in body.script if s.twist is not None and s.t_s <= end]  # fmt: skip
        given = [(stamp_ns / 1e9, (c.surge, c.yaw_rate)) for stamp_ns, c in run.twist(vid)]
        twist = given or scripted  # every one recorded (sent, scripted), else the script's
        if twist:
            values = np.array([w for _, w in twist])
            names = ("surge [m/s]", "yaw rate [rad/s]")
            out.setpoint[vid] = Series(np.array([t for t, _ in twist]), values, names)


def _sensors(run: RecordedRun, out: RunSeries) -> None:
    for sensor in run.world.sensors:
        owner = f"{sensor.vessel}.{sensor.config.name}"
        if sensor.config.type == "imu":
            samples = list(run.imu(sensor))
            if samples:
                t = np.array([s.stamp_ns / 1e9 for s in samples])
                values = np.array([(*s.linear_acceleration, *s.angular_velocity) for s in samples])
                names = ("ax", "ay", "az", "gx", "gy", "gz")
                out.imu[owner] = Series(t, values, names)
        elif sensor.config.type == "lidar":
            counts = [(s.stamp_ns / 1e9, len(s.points), int(s.is_rain.sum()))
                      for s in run.lidar_scans(sensor)]  # fmt: skip
            if counts:
                table = np.array(counts, dtype=np.float64)
                out.lidar[owner] = Series(table[:, 0], table[:, 1:], ("returns", "rain returns"))


def _thruster_names(thrusters: Sequence[Thruster], n: int) -> tuple[str, ...]:
    """ "thruster 0 (port)": which side each is on, from its y (FLU: + is port)."""
    sides = ["port" if t.position_m[1] > 0 else "starboard" if t.position_m[1] < 0 else "centre"
             for t in thrusters]  # fmt: skip
    return tuple(f"thruster {i}" + (f" ({sides[i]})" if i < len(sides) else "") for i in range(n))
