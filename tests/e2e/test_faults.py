"""Faults: a killed service, a hanging participant, Ctrl-C, bad payloads on the bus."""

from __future__ import annotations

import json
import math
import os
import pty
import signal
import subprocess
import sys
import time
from datetime import datetime
from pathlib import Path

import psutil
import pytest
from conftest import (
    REPO,
    basic_scenario,
    csv_rows,
    matched_publisher,
    only_run_dir,
    scenario_file,
    service_pid,
    start,
    wait_for_line,
)

from catabot.bus import codec
from catabot.bus.clock import LAUNCHER_GONE
from catabot.bus.keys import Keys
from catabot.bus.messages import ThrustCmd
from catabot.bus.session import Connection, free_port, open_session
from catabot.config.scenario import ClockConfig
from catabot.run.recorded import RecordedRun
from services.recorder.mcap_read import read_mcap_messages

HERE = Path(__file__).parent


def _long(tmp: Path, **clock: object) -> Path:
    data = basic_scenario("faults", duration_s=600.0)
    data["clock"] = {"realtime_factor": 2.0, **clock}
    return scenario_file(tmp, data)


def _assert_readable(run: Path) -> int:
    rows = csv_rows(run / "vessel.ego.state.csv")
    assert all(len(r) == len(rows[0]) for r in rows), "a CSV row is torn"
    msgs = read_mcap_messages(run / "run.mcap")
    assert len(msgs) >= len(rows) - 1 > 10
    return int(rows[-1][1])


def test_sigkill_of_a_service_ends_the_run_naming_it(tmp_path: Path, out: Path) -> None:
    proc = start("run", str(_long(tmp_path)), "--out", str(out), "--quiet")
    wait_for_line(proc, "zenoh:")
    _wait_for_rows(out, 20)
    os.kill(service_pid(proc.pid, "services.physics"), signal.SIGKILL)
    killed = time.monotonic()
    _, err = proc.communicate(timeout=30)
    assert proc.returncode == 1
    run = only_run_dir(out)
    log = (run / "log" / "conductor.log").read_text()
    assert "'physics' left the run" in log and "physics" in err and "SIGKILL" in err
    assert time.monotonic() - killed < 5.0
    assert _assert_readable(run) > 0


def test_sigterm_of_a_service_is_named_as_such(tmp_path: Path, out: Path) -> None:
    """A process manager's SIGTERM: the service said so in its own log only, and the
    conductor named it as one that left "without a word"."""
    proc = start("run", str(_long(tmp_path)), "--out", str(out), "--quiet")
    wait_for_line(proc, "zenoh:")
    _wait_for_rows(out, 20)
    os.kill(service_pid(proc.pid, "services.physics"), signal.SIGTERM)
    _, err = proc.communicate(timeout=30)
    assert proc.returncode == 1
    log = (only_run_dir(out) / "log" / "conductor.log").read_text()
    assert "participant 'physics' " in log and "stopped by SIGTERM (exit 143)" in log, log
    assert "without a word" not in log and "stopped by SIGTERM" in err


def test_killed_participant_is_detected_within_one_second(tmp_path: Path, out: Path) -> None:
    endpoint = f"tcp/127.0.0.1:{free_port()}"
    scenario = _long(tmp_path, external_participants=["autopilot"])
    proc = start("run", str(scenario), "--out", str(out), "--quiet", "--listen", endpoint)
    wait_for_line(proc, "zenoh:")
    ext = subprocess.Popen(
        [
            sys.executable,
            str(HERE / "hang_participant.py"),
            endpoint,
            "faults",
            "autopilot",
            "300",
            "kill",
        ],
        cwd=REPO,
    )
    ext.wait(timeout=60)
    killed = time.time()
    _, err = proc.communicate(timeout=30)
    assert proc.returncode == 1 and "'autopilot' left the run" in err
    run = only_run_dir(out)
    assert _logged_at(run / "log" / "conductor.log", "run ended by a fault") - killed < 1.0
    _assert_recorded_through(run, 299)


WINDOW = ClockConfig().window_ticks  # the default


def _assert_recorded_through(run: Path, last_complete: int) -> None:
    """Every tick up to the last complete one is on disk; the healthy participants may have
    stepped on inside the window, and what they produced there is kept too."""
    last = _assert_readable(run)
    assert last_complete <= last < last_complete + WINDOW, f"last recorded tick {last}"


def _logged_at(log: Path, needle: str) -> float:
    """Wall time of the log line holding `needle` (logging's asctime, local time)."""
    line = next(x for x in log.read_text().splitlines() if needle in x)
    stamp = datetime.strptime(line[:23], "%Y-%m-%d %H:%M:%S,%f")
    return stamp.timestamp()


def _with_external(scenario: Path, out: Path, *, at: int, how: str) -> tuple[int, str]:
    """Run a scenario beside an external lockstep participant that hangs or dies at `at`."""
    endpoint = f"tcp/127.0.0.1:{free_port()}"
    proc = start("run", str(scenario), "--out", str(out), "--quiet", "--listen", endpoint)
    wait_for_line(proc, "zenoh:")
    cmd = [sys.executable, str(HERE / "hang_participant.py"), endpoint, "faults", "autopilot"]
    ext = subprocess.Popen([*cmd, str(at), how], cwd=REPO)
    try:
        _, err = proc.communicate(timeout=60)
    finally:
        ext.kill()
    return proc.returncode, err


def test_hanging_participant_misses_the_deadline(tmp_path: Path, out: Path) -> None:
    # 2 s: under CI's load the recorder once missed a 1 s deadline at tick 1, before the hang
    scenario = _long(tmp_path, external_participants=["autopilot"], deadline_s=2.0)
    code, err = _with_external(scenario, out, at=100, how="hang")
    assert code == 1
    assert "'autopilot' missed the 2 s deadline of tick 100" in err
    _assert_recorded_through(only_run_dir(out), 99)


def test_drop_policy_goes_on_without_the_hanging_participant(tmp_path: Path, out: Path) -> None:
    data = basic_scenario("faults", duration_s=3.0)
    data["clock"] = {"external_participants": ["autopilot"], "deadline_s": 2.0, "policy": "drop"}
    code, err = _with_external(scenario_file(tmp_path, data), out, at=50, how="hang")
    assert code == 0, err
    run = only_run_dir(out)
    assert "dropping it" in (run / "log" / "conductor.log").read_text()
    assert _assert_readable(run) == 299


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM])
def test_ctrl_c_ends_every_process_with_complete_files(
    tmp_path: Path, out: Path, sig: signal.Signals
) -> None:
    """Ctrl-C, and a SIGTERM from a shell or a process manager, end the run cleanly."""
    proc = start("run", str(_long(tmp_path)), "--out", str(out), "--quiet")
    wait_for_line(proc, "zenoh:")
    _wait_for_rows(out, 20)
    children = psutil.Process(proc.pid).children(recursive=True)
    proc.send_signal(sig)
    _, err = proc.communicate(timeout=30)
    assert proc.returncode == 130, err
    assert not [c for c in children if c.is_running() and c.status() != psutil.STATUS_ZOMBIE]
    run = only_run_dir(out)
    _assert_readable(run)
    assert json.loads((run / "metrics.json").read_text())["end_reason"] == "interrupted"
    from mcap.reader import make_reader

    with (run / "run.mcap").open("rb") as f:
        assert make_reader(f).get_summary() is not None, "MCAP closed with a summary"


def test_a_closed_terminal_ends_the_run_with_its_files_and_run_json(
    tmp_path: Path, out: Path
) -> None:
    """The terminal window closed under `catabot run`: SIGHUP to its process group, and every
    write to the terminal fails with EIO from then on. The launcher died at its next progress
    line, leaving no log/run.json; now the run ends as interrupted, as for Ctrl-C."""
    main, terminal = pty.openpty()
    proc = subprocess.Popen(
        [sys.executable, "-m", "catabot", "run", str(_long(tmp_path)), "--out", str(out)],
        stdin=terminal, stdout=terminal, stderr=terminal, cwd=REPO, start_new_session=True,
    )  # fmt: skip
    os.close(terminal)
    try:
        _wait_for_rows(out, 20)
    finally:
        os.close(main)  # the window closes: the progress bar's next write fails
        os.killpg(proc.pid, signal.SIGHUP)
    assert proc.wait(timeout=30) == 130
    run = only_run_dir(out)
    assert json.loads((run / "log" / "run.json").read_text())["reason"] == "interrupted"
    _assert_readable(run)


def _wait_for_rows(out: Path, rows: int, limit_s: float = 30.0) -> None:
    """Until the run has recorded `rows` states (it has started, whatever the machine's load)."""
    end = time.monotonic() + limit_s
    while time.monotonic() < end:
        states = list(out.glob("*/vessel.ego.state.csv"))
        if states and len(states[0].read_bytes().splitlines()) > rows:
            return
        time.sleep(0.1)
    raise AssertionError(f"no {rows} states recorded in {limit_s} s")


def test_a_stop_before_the_services_join_ends_the_run_cleanly(tmp_path: Path, out: Path) -> None:
    """Ctrl-C while the services are still starting: exit 130, nobody blamed, no orphans."""
    proc = start("run", str(_long(tmp_path)), "--out", str(out), "--quiet")
    wait_for_line(proc, "zenoh:")
    children = psutil.Process(proc.pid).children(recursive=True)
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=30)
    assert proc.returncode == 130, err
    assert "failed" not in err and "Traceback" not in err
    assert not [c for c in children if c.is_running() and c.status() != psutil.STATUS_ZOMBIE]


def test_killed_launcher_leaves_no_orphans(tmp_path: Path, out: Path) -> None:
    """SIGKILL of `catabot run` (no handler runs): the conductor finds its stdout gone at
    the next progress line and ends the run, so every service flushes and exits. Its
    log/run.json, written at the start, still says what ran (it had none at all)."""
    proc = start("run", str(_long(tmp_path)), "--out", str(out), "--quiet")
    wait_for_line(proc, "zenoh:")
    _wait_for_rows(out, 20)
    children = psutil.Process(proc.pid).children(recursive=True)
    proc.kill()
    proc.communicate(timeout=10)
    _, alive = psutil.wait_procs(children, timeout=30)
    assert not alive, [c.cmdline()[2:4] for c in alive]
    run = only_run_dir(out)
    _assert_readable(run)
    record = json.loads((run / "log" / "run.json").read_text())
    assert record["reason"] == "running" and record["launcher_pid"] == proc.pid
    assert record["scenario"] == "faults" and record["command"][:2] == ["catabot", "run"]
    assert RecordedRun(run).end_reason() == LAUNCHER_GONE  # the recorder's account


def test_malformed_and_non_finite_commands_are_logged_and_survived(
    tmp_path: Path, out: Path
) -> None:
    endpoint = f"tcp/127.0.0.1:{free_port()}"
    data = basic_scenario("faults", duration_s=8.0)
    data["clock"] = {"realtime_factor": 2.0}
    proc = start(
        "run",
        str(scenario_file(tmp_path, data)),
        "--out",
        str(out),
        "--quiet",
        "--listen",
        endpoint,
    )
    wait_for_line(proc, "zenoh:")
    key = Keys("faults").cmd_thrust("ego")
    with open_session(Connection(connect=(endpoint,))) as session:
        pub = matched_publisher(session, key)
        for payload in (
            b"\x93garbage",
            codec.encode(ThrustCmd(thrust=(math.nan, 0.5))),
            codec.encode(ThrustCmd(thrust=(math.inf, 0.5))),
            codec.encode(ThrustCmd(thrust=(0.5,))),
        ):
            pub.put(payload)
            time.sleep(0.2)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 0, err
    run = only_run_dir(out)
    log = (run / "log" / "physics.log").read_text()
    assert f"refused a sample on {key}: malformed" in log
    assert f"refused a sample on {key}: invalid content" in log  # then counted, not repeated
    counts = json.loads((run / "log" / "physics.rejected.json").read_text())  # where they land
    assert counts == {"invalid content": 3, "malformed": 1}
    assert json.loads((run / "log" / "run.json").read_text())["rejected"]["physics"] == counts
