"""The client API against real runs (`catabot run --listen`): a stack that observes and
commands, one whose run ends while it waits, late and unexpected joiners, and a lockstep
stack reading sensors whose run records the same bytes twice."""

from __future__ import annotations

import json
import logging
import os
import signal
import time
from pathlib import Path
from typing import Any

import pytest
from conftest import files_of, only_run_dir, scenario_file, service_pid, start

from catabot.bus.messages import GpsFix, ImuSample, VesselState
from catabot.bus.session import free_port
from catabot.client import (
    Client,
    ClientError,
    CommandError,
    NotAParticipant,
    Observation,
    RunEnded,
    SimulatorNotFound,
    Thrust,
    TooLate,
    UnknownSensor,
    UnknownVessel,
    WrongRate,
)

pytestmark = pytest.mark.timeout(180)
SENSORS = [{"name": "gps", "type": "gps", "rate_hz": 10.0},
           {"name": "imu", "type": "imu", "rate_hz": 50.0}]  # fmt: skip


class Run:
    def __init__(self, tmp: Path, data: dict[str, Any], *flags: str) -> None:
        self.endpoint, self.out = f"tcp/127.0.0.1:{free_port()}", tmp / "out"
        tmp.mkdir(parents=True, exist_ok=True)
        path = scenario_file(tmp, data)
        self.proc = start("run", str(path), "--quiet", "--out", str(self.out),
                          "--listen", self.endpoint, *flags)  # fmt: skip

    def finish(self, code: int = 0) -> Path:
        out, err = self.proc.communicate(timeout=120)
        assert self.proc.returncode == code, out + err
        return only_run_dir(self.out)

    def kill(self) -> None:
        if self.proc.poll() is None:
            self.proc.kill()
            self.proc.wait()


def _run(tmp: Path, data: dict[str, Any], *flags: str) -> Run:
    return Run(tmp, data, *flags)


def test_no_simulation_running_is_simulator_not_found_after_the_timeout() -> None:
    started = time.monotonic()
    with pytest.raises(SimulatorNotFound, match="no simulation of any world answered"):
        Client.connect([f"tcp/127.0.0.1:{free_port()}"], timeout_s=1.0)
    assert 1.0 <= time.monotonic() - started < 5.0


def test_a_free_running_stack_observes_and_commands(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    data = {"name": "free", "seed": 1, "duration_s": 16.0, "clock": {"realtime_factor": 2.0},
            "vessels": [{"id": "ego", "sensors": SENSORS}]}  # fmt: skip
    run = _run(tmp_path, data)
    try:
        with Client.connect([run.endpoint], timeout_s=30) as sim:
            with pytest.raises(UnknownVessel, match="no vessel 'ego2'; its vessels: ego"):
                sim.vessel("ego2")
            ego = sim.vessel("ego")
            with pytest.raises(UnknownSensor, match="no sensor 'lidar'; its sensors: gps, imu"):
                ego.sensor("lidar")
            assert isinstance(ego.state(timeout_s=10), VesselState)
            assert isinstance(ego.sensor("gps").latest(timeout_s=5), GpsFix)
            imu: list[ImuSample] = []
            ego.sensor("imu").on_sample(imu.append)
            with pytest.raises(CommandError, match="1 values for 2 thrusters"):
                ego.send(Thrust([0.5]))
            seen: list[Observation] = []

            def step(obs: Observation) -> Thrust:
                seen.append(obs)
                return Thrust([0.25, -0.5])

            assert (
                sim.run_free(step, rate_hz=10, vessel="ego", sensors=["gps"], max_steps=5) is None
            )
            assert len(seen) == 5 and all(o.state is not None for o in seen)
            assert seen[-1].tick > seen[0].tick and isinstance(seen[-1].sensors["gps"], GpsFix)
            slow = lambda _: time.sleep(0.15)  # noqa: E731  # ran at 1/0.15 Hz, unsaid
            with caplog.at_level(logging.WARNING, logger="catabot.client"):
                sim.run_free(slow, rate_hz=10, vessel="ego", max_steps=3)
            said = [r.getMessage() for r in caplog.records if "a step took" in r.getMessage()]
            assert len(said) == 1 and "longer than its period (0.1 s, rate_hz 10)" in said[0]
            assert len(imu) > 10 and all(isinstance(s, ImuSample) for s in imu)
            started = time.monotonic()
            with pytest.raises(RunEnded, match=r"ended at tick 1599 \(completed\)"):
                while True:  # polling after the end is RunEnded, never a stale state forever
                    ego.state(timeout_s=2)
                    time.sleep(0.1)
            assert time.monotonic() - started < 30
        run_dir = run.finish()
    finally:
        run.kill()
    rows = (run_dir / "vessel.ego.cmd.thrust.csv").read_text().splitlines()
    assert [r.split(",")[2:] for r in rows[1:]] == [["0.25", "-0.5"]] * 5
    assert json.loads((run_dir / "log" / "run.json").read_text())["rejected"] == {}


def test_the_run_ending_while_a_stack_waits_is_run_ended(tmp_path: Path) -> None:
    clock = {"external_participants": ["stack", "absent"], "start_timeout_s": 5.0}
    data = {"name": "ending", "duration_s": 2.0, "vessels": [{"id": "ego"}], "clock": clock}
    run = _run(tmp_path, data)
    try:
        with Client.connect([run.endpoint], timeout_s=30) as sim:
            with pytest.raises(NotAParticipant, match="expects stack, absent"):
                sim.join("intruder")
            stack = sim.join("stack")
            with Client.connect([run.endpoint], timeout_s=10) as other:
                time.sleep(0.5)  # its tokens arrive
                with pytest.raises(TooLate, match="'stack' of world 'ending' is already joined"):
                    other.join("stack")
            started = time.monotonic()
            with pytest.raises(RunEnded, match="never joined within 5 s: absent") as ended:
                stack.observe()
            assert ended.value.reason == "fault" and time.monotonic() - started < 20
            with pytest.raises(RunEnded, match="has ended"):
                stack.observe()
        run.finish(code=1)
    finally:
        run.kill()


def test_a_conductor_that_dies_while_a_stack_waits_is_run_ended(tmp_path: Path) -> None:
    ego = {"id": "ego", "controller": {"participant": "stack", "rate_hz": 10.0}}
    run = _run(tmp_path, {"name": "dies", "duration_s": 60.0, "vessels": [ego],
                          "clock": {"realtime_factor": 1.0}})  # fmt: skip
    try:
        with Client.connect([run.endpoint], timeout_s=30) as sim:
            stack = sim.join("stack")
            for _ in range(3):
                stack.observe()
                stack.act(Thrust([0.2, 0.2]))
            os.kill(service_pid(run.proc.pid, "catabot.run.conduct"), signal.SIGKILL)
            started = time.monotonic()
            with pytest.raises(RunEnded, match="the conductor vanished without an End reaching it"):
                while True:
                    stack.observe()  # act(None) implied: keep the last command
            assert time.monotonic() - started < 15
        run.proc.wait(timeout=60)
        assert run.proc.returncode != 0
    finally:
        run.kill()


def test_a_stack_leaving_mid_run_is_named_and_the_run_ends(tmp_path: Path) -> None:
    ego = {"id": "ego", "controller": {"participant": "stack", "rate_hz": 10.0}}
    run = _run(tmp_path, {"name": "leaves", "duration_s": 60.0, "vessels": [ego]})
    try:
        with Client.connect([run.endpoint], timeout_s=30) as sim:
            with pytest.raises(WrongRate, match=r"rate_hz 5: 'stack' steps as ego's controller, "
                               r"at its controller.rate_hz 10 Hz; leave rate_hz out"):  # fmt: skip
                sim.join("stack", rate_hz=5)  # taken silently, and stepped at 10 Hz
            with pytest.raises(WrongRate, match=r"rate_hz 7: period 142857143 ns is not a whole"):
                sim.join("stack", rate_hz=7)  # a plain ValueError, not a ClientError
            for bad in (0.0, float("nan")):  # a ZeroDivisionError, a ValueError
                with pytest.raises(WrongRate, match=r"must be a finite number > 0"):
                    sim.join("stack", rate_hz=bad)
            stack = sim.join("stack", rate_hz=10)
            with pytest.raises(ClientError, match=r"stack: act\(\) first: one act\(\) answers"):
                stack.act(Thrust([0.2, 0.2]))
            for _ in range(3):
                stack.observe()
                stack.act(Thrust([0.2, 0.2]))
            with pytest.raises(
                ClientError, match=r"act\(\) again for tick 20: one act\(\) answers"
            ):
                stack.act(Thrust([0.2, 0.2]))  # said "act() before observe()"
            stack.observe()
            started = time.monotonic()
            stack.close()  # while the participant waits for this period's command
            assert time.monotonic() - started < 6
        out, err = run.proc.communicate(timeout=60)
        said = "participant 'stack' stopped at tick 30: closed by its stack before the run's end"
        assert run.proc.returncode == 1 and said in err, out + err  # not "without a word"
    finally:
        run.kill()


def _lockstep(tmp: Path) -> tuple[dict[str, bytes], list[Observation]]:
    controller = {"participant": "stack", "rate_hz": 10.0, "command": "thrust"}
    ego = {"id": "ego", "sensors": SENSORS, "controller": controller}
    run = _run(tmp, {"name": "steps", "seed": 4, "duration_s": 3.0, "vessels": [ego]})
    seen: list[Observation] = []

    def step(obs: Observation) -> Thrust:
        seen.append(obs)
        gps = obs.sensors["gps"]
        turn = 0.0 if gps is None else (gps.latitude * 1e4) % 1.0 - 0.5  # noisy: sensors matter
        return Thrust([0.6 - 0.4 * turn, 0.6 + 0.4 * turn + 0.01 * len(obs.samples["imu"])])

    try:
        with Client.connect([run.endpoint], timeout_s=30) as sim:
            end = sim.run_lockstep("stack", step, sensors=["gps", "imu"])
        assert (end.tick, end.reason) == (299, "completed")
        return files_of(run.finish()), seen
    finally:
        run.kill()


def test_a_lockstep_stack_with_sensors_records_the_same_bytes_twice(tmp_path: Path) -> None:
    first, seen = _lockstep(tmp_path / "a")
    second, _ = _lockstep(tmp_path / "b")
    assert sorted(first) == sorted(second) and "vessel.ego.cmd.thrust.csv" in first
    assert [n for n in first if first[n] != second[n]] == []
    assert [o.tick for o in seen] == list(range(0, 300, 10))
    # Jacobi: the observation of tick k holds the state at t_k and samples tagged before k
    assert seen[0].bodies.tick == -1 and seen[0].sensors == {"gps": None, "imu": None}
    for obs in seen[1:]:
        assert obs.bodies.tick == obs.tick - 1 and obs.stamp_ns == obs.tick * 10**7
        assert obs.sensors["gps"].tick == obs.tick - 10
        assert [s.tick for s in obs.samples["imu"]] == list(range(obs.tick - 10, obs.tick, 2))
    commands = first["vessel.ego.cmd.thrust.csv"].decode().splitlines()
    assert [c.split(",")[1] for c in commands[1:]] == [str(k) for k in range(0, 300, 10)]
