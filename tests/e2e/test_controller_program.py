"""`vessels[].controller.program`: `catabot run` starts the stack as one more participant."""

from __future__ import annotations

import json
import re
from pathlib import Path
from typing import Any

from conftest import basic_scenario, catabot, csv_rows, files_of, only_run_dir, scenario_file

PROGRAM = "tests/e2e/stack_program.py"  # from the repository root: the current directory


def _scenario(tmp: Path, *args: str, program: str = PROGRAM, **top: Any) -> Path:
    data: dict[str, Any] = basic_scenario("program", duration_s=3.0, **top)
    data["vessels"][0] = {
        "id": "ego",
        "pose": {"x_m": 0.0, "y_m": 0.0, "yaw_rad": 0.0},
        "controller": {"participant": "stack", "rate_hz": 10.0, "program": program,
                       "args": list(args)},
    }  # fmt: skip
    return scenario_file(tmp, data)


def _run(tmp: Path, scenario: Path, tag: str) -> tuple[int, str, Path | None]:
    out = tmp / tag
    out.mkdir()
    result = catabot("run", str(scenario), "--out", str(out), "--quiet")
    runs = list(out.iterdir())
    return result.returncode, result.stdout + result.stderr, only_run_dir(out) if runs else None


def test_a_program_driven_vessel_records_the_same_bytes_twice(tmp_path: Path) -> None:
    scenario = _scenario(tmp_path, "--goal", "30", "10")
    code_a, said_a, run_a = _run(tmp_path, scenario, "a")
    code_b, said_b, run_b = _run(tmp_path, scenario, "b")
    assert code_a == 0 and code_b == 0, said_a + said_b
    assert run_a is not None and run_b is not None
    assert files_of(run_a) == files_of(run_b)
    rows = csv_rows(run_a / "vessel.ego.state.csv")
    x = [float(r[rows[0].index("position_x[m]")]) for r in rows[1:]]
    assert x[-1] > 1.0  # the program's thrust moved the boat
    assert "stack ended at tick" in (run_a / "log" / "stack.log").read_text()  # its stdout
    record = json.loads((run_a / "log" / "run.json").read_text())
    assert record["services"]["stack"] == 0  # counted with the services


def test_a_program_crashing_mid_run_is_named_as_the_cause(tmp_path: Path) -> None:
    code, said, run = _run(tmp_path, _scenario(tmp_path, "--crash-at", "120"), "crash")
    assert code == 1, said
    cause = next(line for line in said.splitlines() if line.startswith("run failed:"))
    assert "stack" in cause and "stack_program.py" in cause, cause
    assert "ZeroDivisionError: the stack fell over at tick 120" in cause
    assert (
        run is not None and json.loads((run / "metrics.json").read_text())["end_reason"] == "fault"
    )
    assert run is not None and "Traceback" in (run / "log" / "stack.log").read_text()


def test_a_missing_program_is_refused_before_anything_starts(tmp_path: Path) -> None:
    code, said, run = _run(tmp_path, _scenario(tmp_path, program="no/such/stack.py"), "missing")
    assert code == 2 and run is None
    assert "vessels.0.controller.program: 'no/such/stack.py' is not a file" in said


def test_a_programs_nan_command_is_refused_and_its_tick_goes_on(tmp_path: Path) -> None:
    """Physics and the recorder waited for a valid command for tick 100 until the deadline,
    which then blamed physics: now both refuse it, the run goes on with the order in force,
    and the refusal is on the console."""
    code, said, run = _run(tmp_path, _scenario(tmp_path, "--nan-at", "100"), "nan")
    assert code == 0 and run is not None, said
    assert "refused" in said and "not finite" in said and "tick 100 goes on without it" in said
    rows = csv_rows(run / "vessel.ego.cmd.thrust.csv")
    ticks = [int(r[rows[0].index("tick")]) for r in rows[1:]]
    assert 100 not in ticks and 90 in ticks and 110 in ticks


def test_a_program_that_acks_a_tick_without_its_command_is_named(tmp_path: Path) -> None:
    """Physics waits for the command the stack owed; the deadline names physics (it did not
    ack), and the cause now says whose data it waited for."""
    scenario = _scenario(tmp_path, "--skip-at", "100", clock={"deadline_s": 2.0})
    code, said, _ = _run(tmp_path, scenario, "skip")
    assert code == 1, said
    cause = next(line for line in said.splitlines() if line.startswith("run failed:"))
    assert "missed the 2 s deadline of tick 101" in cause, cause
    assert "waited at tick 101 for catabot/program/vessel/ego/cmd/thrust from 'stack'" in cause


def test_a_program_slower_than_a_short_deadline_is_named_not_physics(tmp_path: Path) -> None:
    """Under a 1 s deadline a stack asleep in tick 100 had physics named: waiting at 101 for
    its command, physics acked the ticks it had stepped only after a second without events.
    A waiting participant now acks within a quarter of the deadline."""
    scenario = _scenario(tmp_path, "--sleep-at", "100", "1.5", clock={"deadline_s": 1.0})
    code, said, _ = _run(tmp_path, scenario, "slow")
    assert code == 1, said
    cause = next(line for line in said.splitlines() if line.startswith("run failed:"))
    assert cause.startswith("run failed: participant 'stack' missed the 1 s deadline of tick 100")


def test_a_slow_program_dropped_under_policy_drop_is_told_and_stops(tmp_path: Path) -> None:
    """It stepped on through every queued tick, its commands taken by nobody, and heard
    "completed" at the end; a grant naming it dropped now ends its own run there."""
    clock = {"deadline_s": 1.0, "policy": "drop"}
    code, said, run = _run(
        tmp_path, _scenario(tmp_path, "--sleep-at", "100", "1.5", clock=clock), "d"
    )
    assert code == 0 and run is not None, said
    assert "stack: dropped, the run went on without it" in said
    log = (run / "log" / "stack.log").read_text()
    # within a window (40 ticks) of its sleep at 100, far from the run's end at 299: a loaded
    # machine had it step the grants queued before the one naming it dropped (139)
    assert re.search(r"^stack ended at tick 1[0-4]\d \(dropped\)$", log, re.M), log
    assert "waited" not in log


def test_a_program_that_ends_before_joining_fails_the_run_at_once(tmp_path: Path) -> None:
    """It exited 0, and the run waited out the 60 s start timeout for it."""
    code, said, run = _run(tmp_path, _scenario(tmp_path, "--leave"), "leave")
    assert code == 1, said
    cause = next(line for line in said.splitlines() if line.startswith("run failed:"))
    assert "stack_program.py ended (exit code 0) before the run started" in cause, cause
    assert "never joined" not in said
    assert run is not None  # a fault, not "interrupted" as Ctrl-C (a sweep tests for it)
    assert json.loads((run / "log" / "run.json").read_text())["reason"] == "fault"


def test_a_program_still_running_after_the_run_is_stopped_not_failed(tmp_path: Path) -> None:
    """A stack that spins on after `run_lockstep` returned turned a completed run into a
    failure (its SIGTERM exit code)."""
    code, said, run = _run(tmp_path, _scenario(tmp_path, "--linger"), "linger")
    assert code == 0 and run is not None, said
    assert "stack: still running 5 s after the run ended, so stopped" in said
    record = json.loads((run / "log" / "run.json").read_text())
    assert record["error"] == "" and record["reason"] == "completed"


def test_under_policy_drop_a_crashed_programs_vessel_is_handed_back(tmp_path: Path) -> None:
    """Under `clock.policy: drop` a crashed stack's boat sailed on at its last thrust to the
    end, and only conductor.log said anything: the recording read as if the stack had
    steered it. Now physics and the recorder hand it back (rest without a script) at one
    tick, the console says so, and run.json and metrics.json name the participant."""
    scenario = _scenario(tmp_path, "--crash-at", "120", clock={"policy": "drop"})
    code, said, run = _run(tmp_path, scenario, "drop")
    assert code == 0 and run is not None, said
    told = re.search(r"stack left the run at t = ([\d.]+) s \(clock.policy drop\): ego back", said)
    assert told is not None, said
    since_s = float(told[1])  # its last command was tagged 110: the tick after the next due
    assert since_s == 1.21  # the same on every run (the drop's grant was not: 5.2 or 5.4 s)
    assert "stack: dropped, the run went on without it" in said and "ZeroDivisionError" in said
    assert "taken over" not in said  # its own lockstep thrust was never an outsider's
    assert json.loads((run / "metrics.json").read_text())["dropped"] == {"stack": since_s}
    assert (
        "ZeroDivisionError"
        in json.loads((run / "log" / "run.json").read_text())["dropped"]["stack"]
    )
    rows = csv_rows(run / "vessel.ego.cmd.thrust.csv")
    stamp, *values = rows[-1][0], *rows[-1][2:]
    assert int(stamp) == round(since_s * 1e9) and [float(v) for v in values] == [0.0, 0.0]
    states = csv_rows(run / "vessel.ego.state.csv")
    surge = states[0].index("linear_velocity_x[m/s]")
    at_drop, last = (float(states[round(since_s * 100)][surge]), float(states[-1][surge]))
    assert int(states[-1][1]) == 299 and last < 0.7 * at_drop, (at_drop, last)
