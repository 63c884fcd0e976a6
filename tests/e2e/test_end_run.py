"""A stack ends the run (`Joined.end_run`, `EndRun` from a `run_lockstep` step) against real
`catabot run --listen` runs: a clean end, exit 0, the reason in `log/run.json` and on the
console, the recording up to the last tick stepped and the same bytes on every run."""

from __future__ import annotations

import contextlib
import json
import math
import threading
from pathlib import Path
from typing import Any

import pytest
from conftest import files_of
from test_client import SENSORS, Run

from catabot.client import (
    Client,
    ClientError,
    CommandError,
    EndRun,
    Observation,
    RunEnded,
    Thrust,
)

pytestmark = pytest.mark.timeout(180)
CONTROLLER = {"participant": "stack", "rate_hz": 10.0, "command": "thrust"}
SCENARIO: dict[str, Any] = {
    "name": "ends", "seed": 5, "duration_s": 60.0,
    "vessels": [{"id": "ego", "sensors": SENSORS, "controller": CONTROLLER}],
}  # fmt: skip


def _ended_run(tmp: Path) -> tuple[Path, str, int]:
    """The stack drives for 2.3 s, then ends the run: its folder, console, End tick."""
    run = Run(tmp, SCENARIO)

    def step(obs: Observation) -> Thrust:
        if obs.tick == 230:
            raise EndRun("mission complete")
        return Thrust([0.5, 0.6])

    try:
        with Client.connect([run.endpoint], timeout_s=30) as sim:
            end = sim.run_lockstep("stack", step, sensors=["gps"])
        out, err = run.proc.communicate(timeout=60)
        assert run.proc.returncode == 0, out + err
        return Path(out.split("run folder: ")[-1].strip()), out, end.tick
    finally:
        run.kill()


def test_a_stack_ends_the_run_cleanly_where_it_stopped(tmp_path: Path) -> None:
    run_dir, console, tick = _ended_run(tmp_path / "a")
    reason = "ended by 'stack' after tick 229: mission complete"
    assert tick == 229 and f"run {reason}" in console
    record = json.loads((run_dir / "log" / "run.json").read_text())
    assert (record["error"], record["reason"], record["ticks"]) == ("", reason, 230)
    state = (run_dir / "vessel.ego.state.csv").read_text().splitlines()
    assert state[-1].split(",")[1] == "229"  # the state at t = 2.3 s, what the stack saw last
    commands = (run_dir / "vessel.ego.cmd.thrust.csv").read_text().splitlines()
    assert commands[-1].split(",")[1] == "220"  # no command for the period it ended at
    second, _, _ = _ended_run(tmp_path / "b")
    first, again = files_of(run_dir), files_of(second)
    assert [n for n in first if first[n] != again.get(n)] == []


def test_end_run_is_refused_before_observe_and_without_a_reason(tmp_path: Path) -> None:
    run = Run(tmp_path, SCENARIO)
    try:
        with Client.connect([run.endpoint], timeout_s=30) as sim:
            stack = sim.join("stack")
            with pytest.raises(ClientError, match=r"none is waiting .* call observe\(\)"):
                stack.end_run("too early")  # before the first observe()
            stack.observe()
            stack.act(Thrust([0.1, 0.1]))
            with pytest.raises(ClientError, match="or it was acted on"):
                stack.end_run("after act")  # said "before observe()", and it had observed
            stack.observe()
            for bad in ("", "x" * 201, "tab\there"):
                with pytest.raises(ClientError, match="1-200 printable characters"):
                    stack.end_run(bad)
            end = stack.end_run("checked")  # still in the seat: the refusals sent nothing
            assert (end.tick, end.reason) == (9, "ended by 'stack' after tick 9: checked")
            for late in (lambda: stack.end_run("again"), lambda: stack.act(Thrust([0.1, 0.1]))):
                with pytest.raises(RunEnded, match="has ended \\(ended by 'stack'"):
                    late()  # it said "before observe()"
            stack.close()
        out, err = run.proc.communicate(timeout=60)
        assert run.proc.returncode == 0, out + err
    finally:
        run.kill()


def _watched_run(tmp: Path) -> tuple[Path, int]:
    """A stack drives the ego; a second participant, driving nothing, ends the run at its
    sixth period: physics and the recorder may have stepped a window ahead of it."""
    data = dict(SCENARIO, clock={"external_participants": ["watcher"]})
    run = Run(tmp, data)
    ended: list[int] = []

    def drive() -> None:
        with Client.connect([run.endpoint], timeout_s=30) as sim:
            stack = sim.join("stack")
            with contextlib.suppress(RunEnded):
                while True:
                    stack.observe()
                    stack.act(Thrust([0.5, 0.6]))

    driver = threading.Thread(target=drive, daemon=True)
    driver.start()
    try:
        with Client.connect([run.endpoint], timeout_s=30) as sim:
            watcher = sim.join("watcher", rate_hz=100.0)
            for _ in range(6):
                watcher.observe()
            ended.append(watcher.end_run("seen enough").tick)
        driver.join(60)
        out, err = run.proc.communicate(timeout=60)
        assert run.proc.returncode == 0, out + err
        return Path(out.split("run folder: ")[-1].strip()), ended[0]
    finally:
        run.kill()


def test_a_participant_that_drives_nothing_ends_the_recording_at_its_tick(tmp_path: Path) -> None:
    """The recording ran 34 ticks past the End (rows up to tick 38 for an End at 4)."""
    run_dir, tick = _watched_run(tmp_path / "a")
    assert tick == 4
    for name in ("vessel.ego.state.csv", "sensor.ego.gps.csv", "vessel.ego.cmd.thrust.csv"):
        last = (run_dir / name).read_text().splitlines()[-1].split(",")
        assert int(last[1]) <= tick, (name, last[:2])
    assert (run_dir / "vessel.ego.state.csv").read_text().splitlines()[-1].split(",")[1] == "4"
    metrics = json.loads((run_dir / "metrics.json").read_text())
    assert metrics["sim_time_s"] == pytest.approx(0.05)
    again, _ = _watched_run(tmp_path / "b")
    first, second = files_of(run_dir), files_of(again)
    assert [n for n in first if first[n] != second.get(n)] == []


def test_a_stack_that_raises_is_the_runs_cause_in_its_own_words(tmp_path: Path) -> None:
    """Not `EndRun`: a bug. The stack's exception reaches it, and the conductor's error (the
    console, log/run.json) quotes it, where it said only that the stack left."""
    run = Run(tmp_path, SCENARIO)

    def step(obs: Observation) -> Thrust:
        if obs.tick == 50:
            raise ZeroDivisionError("division by zero")
        return Thrust([0.5, 0.6])

    try:
        with Client.connect([run.endpoint], timeout_s=30) as sim, pytest.raises(ZeroDivisionError):
            sim.run_lockstep("stack", step)
        out, err = run.proc.communicate(timeout=60)
        cause = "participant 'stack' stopped at tick 50: ZeroDivisionError: division by zero"
        assert run.proc.returncode != 0 and cause in err, out + err
        run_dir = Path(out.split("run folder: ")[-1].strip())
        record = json.loads((run_dir / "log" / "run.json").read_text())
        assert (record["error"], record["ticks"]) == (cause, 50)  # every tick it stepped
        state = (run_dir / "vessel.ego.state.csv").read_text().splitlines()
        assert state[-1].split(",")[1] == "49"  # it had 40: the fault's ack did not count
    finally:
        run.kill()


def test_a_command_the_client_refuses_is_the_runs_cause_too(tmp_path: Path) -> None:
    """A NaN returned from a step: act() refused it outside the step's guard, and the run
    said only that the stack left without a word."""
    run = Run(tmp_path, SCENARIO)

    def step(obs: Observation) -> Thrust:
        return Thrust([math.nan if obs.tick == 50 else 0.5, 0.6])

    try:
        with Client.connect([run.endpoint], timeout_s=30) as sim, pytest.raises(CommandError):
            sim.run_lockstep("stack", step)
        out, err = run.proc.communicate(timeout=60)
        cause = "participant 'stack' stopped at tick 50: CommandError: "
        assert run.proc.returncode != 0 and cause in err and "not finite" in err, out + err
    finally:
        run.kill()


def test_a_pull_style_stack_that_raises_is_the_cause_too(tmp_path: Path) -> None:
    """join/observe/act inside `with Client.connect(...)`: the exception leaving the block
    is told (it said only "participant 'stack' left the run at tick 40")."""
    run = Run(tmp_path, SCENARIO)
    try:
        with pytest.raises(KeyError), Client.connect([run.endpoint], timeout_s=30) as sim:
            stack = sim.join("stack")
            while stack.observe().tick < 50:
                stack.act(Thrust([0.5, 0.6]))
            raise KeyError("waypoint 7")
        out, err = run.proc.communicate(timeout=60)
        assert "participant 'stack' stopped at tick 50: KeyError: 'waypoint 7'" in err, out + err
    finally:
        run.kill()
