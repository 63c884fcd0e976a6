"""A run whose processes are started one by one (`catabot service ...`, as on several hosts):
what a user gets wrong there is refused at once and named, not left to a deadline.

- a process given another scenario file than the conductor's (a pose, a rate) stops with
  the reason, which the conductor's error repeats; before, the run completed with a world
  nobody described;
- one whose file names other participants than the conductor's (no tick would ever come)
  stops at its first note that no tick came;
- a second physics, or a second conductor, of a world already running stops; the run that
  was there goes on;
- the recorder leaves the scenario and `log/run.json` (how the run ended, what ran it) in its
  run folder, so `catabot plot`, `catabot results` and the other tools read a split run's
  folder.
"""

from __future__ import annotations

import json
import subprocess
import time
from pathlib import Path
from typing import Any

import pytest
from conftest import catabot, scenario_file, start

from catabot.bus.session import free_port
from catabot.run.probe import on_bus, port_open

pytestmark = pytest.mark.timeout(180)
SCENARIO: dict[str, Any] = {
    "name": "split", "seed": 1, "duration_s": 2.0,
    "vessels": [{"id": "ego", "pose": {"x_m": 0.0, "y_m": 0.0}}],
}  # fmt: skip


def _service(name: str, scenario: Path, endpoint: str, *more: str) -> subprocess.Popen[str]:
    return start("service", name, "--scenario", str(scenario), "--connect", endpoint, *more)


def _conductor(scenario: Path, endpoint: str) -> subprocess.Popen[str]:
    return start("service", "conductor", "--scenario", str(scenario), "--listen", endpoint)


def _result(proc: subprocess.Popen[str]) -> dict[str, Any]:
    out, err = proc.communicate(timeout=120)
    lines = [json.loads(x) for x in out.splitlines() if '"result"' in x]
    assert lines, out + err
    return dict(lines[-1])


def test_a_process_given_another_scenario_stops_and_says_why(tmp_path: Path) -> None:
    mine = scenario_file(tmp_path, SCENARIO)
    moved = json.loads(json.dumps(SCENARIO))
    moved["vessels"][0]["pose"]["x_m"] = 5.0
    other = scenario_file(tmp_path, moved, "moved.json")
    endpoint = f"tcp/127.0.0.1:{free_port()}"
    conductor = _conductor(mine, endpoint)
    physics = _service("physics", other, endpoint, "--run-dir", str(tmp_path / "run"))
    recorder = _service("recorder", mine, endpoint, "--run-dir", str(tmp_path / "run"))
    try:
        _, err = physics.communicate(timeout=120)
        assert physics.returncode == 2, err
        assert "the conductor runs another scenario (digest " in err
        assert "give every process of the run the same scenario file" in err
        said = _result(conductor)["error"]
        assert said.startswith(
            "participant 'physics' stopped at tick 0: the conductor runs another scenario (digest "
        )  # its own words, on the clock's host
    finally:
        for proc in (conductor, physics, recorder):
            proc.kill()
            proc.communicate()


def test_a_process_whose_file_needs_other_participants_stops_while_waiting(
    tmp_path: Path,
) -> None:
    """The conductor's file needs a sensors service the other host's file does not (or
    another `traffic.shards`): the conductor waits for it, no tick comes, and physics sat
    out the whole start timeout saying only that no tick came. At its first note (10 s) it
    asks the conductor's world/info and stops on the digest."""
    needs_sensors = json.loads(json.dumps(SCENARIO))
    needs_sensors["vessels"][0]["sensors"] = [{"name": "imu", "type": "imu", "rate_hz": 10.0}]
    endpoint = f"tcp/127.0.0.1:{free_port()}"
    conductor = _conductor(scenario_file(tmp_path, needs_sensors), endpoint)
    other = scenario_file(tmp_path, SCENARIO, "other.json")
    physics = _service("physics", other, endpoint, "--run-dir", str(tmp_path / "run"))
    try:
        _, err = physics.communicate(timeout=50)  # the conductor would wait 60 s
        assert physics.returncode == 2, err
        assert "the conductor runs another scenario (digest " in err
        assert "and gives no tick: it waits for the participants of its file" in err
    finally:
        for proc in (conductor, physics):
            proc.kill()
            proc.communicate()


def _until_joined(endpoint: str, name: str) -> None:
    """Its liveliness token is there (a fixed 2 s sleep lost the race on a loaded machine:
    the second physics joined first and the first one was the one refused)."""
    limit = time.monotonic() + 60
    while port_open(endpoint, 1.0) or on_bus(endpoint, name, None, timeout_s=1.0):
        assert time.monotonic() < limit, f"{name} never joined"
        time.sleep(0.2)


def test_a_second_physics_or_conductor_stops_and_the_run_goes_on(tmp_path: Path) -> None:
    scenario = scenario_file(tmp_path, SCENARIO)
    endpoint, run = f"tcp/127.0.0.1:{free_port()}", tmp_path / "run"
    conductor = _conductor(scenario, endpoint)
    physics = _service("physics", scenario, endpoint, "--run-dir", str(run))
    procs = [conductor, physics]
    try:
        _until_joined(endpoint, "physics")  # the world has its conductor and its physics
        again = _service("physics", scenario, endpoint, "--run-dir", str(tmp_path / "again"))
        rival = start("service", "conductor", "--scenario", str(scenario), "--connect", endpoint)
        procs += [again, rival]
        _, err = again.communicate(timeout=60)
        assert again.returncode == 2 and "another process already runs as 'physics'" in err
        out, err = rival.communicate(timeout=120)
        refused = json.loads([x for x in out.splitlines() if '"result"' in x][-1])
        assert rival.returncode == 2, refused
        said = "another process already runs as 'conductor' in world 'split'"
        assert said in refused["error"] and said in err  # its log says so too, not only stdout
        recorder = _service("recorder", scenario, endpoint, "--run-dir", str(run))
        procs.append(recorder)
        result = _result(conductor)
        assert (result["error"], result["ticks_done"]) == ("", 200), result
        recorder.communicate(timeout=60)
        assert json.loads((run / "scenario.json").read_text())["name"] == "split"
        assert (run / "vessel.ego.state.csv").is_file()
        record = json.loads((run / "log" / "run.json").read_text())  # no launcher wrote one
        assert (record["reason"], record["ticks"], record["sim_s"]) == ("completed", 200, 2.0)
        assert record["written_by"].startswith("recorder") and record["seed"] == 1
        assert record["command"][:3] == ["catabot", "service", "recorder"]
        kept = (run / "run.mcap").read_bytes()
        twice = catabot("service", "recorder", "--scenario", str(scenario), "--listen",
                        f"tcp/127.0.0.1:{free_port()}", "--run-dir", str(run))  # fmt: skip
        assert twice.returncode == 2 and f"run folder {run} already holds a recording (" in (
            twice.stderr
        )  # it overwrote run.mcap and metrics.json, beside the first run's CSVs
        assert (run / "run.mcap").read_bytes() == kept
    finally:
        for proc in procs:
            proc.kill()
            proc.communicate()
