"""The live viewer is an observer: it shows a running simulation and changes nothing of it."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import rerun as rr
from conftest import (
    basic_scenario,
    catabot,
    files_of,
    only_run_dir,
    scenario_file,
    start,
    wait_for_line,
)

from catabot.bus.session import free_port


def _scenario(seconds: float) -> dict[str, Any]:
    data = basic_scenario("live", duration_s=seconds)
    data["vessels"][0]["sensors"] = [
        {"name": "lidar", "type": "lidar", "rate_hz": 10.0, "params": {"columns": 256}},
        {"name": "imu", "type": "imu", "rate_hz": 50.0},
    ]
    data["traffic"] = {"count": 3, "behaviour_mix": {"circle": 1.0}}
    return data


def test_view_attaches_to_a_running_simulation(tmp_path: Path) -> None:
    endpoint = f"tcp/127.0.0.1:{free_port()}"
    scenario = scenario_file(tmp_path, _scenario(8.0))  # the view may start seconds late
    out = tmp_path / "runs"
    sim = start("run", str(scenario), "--out", str(out), "--quiet", "--listen", endpoint,
                "--realtime", "1.0")  # fmt: skip
    try:
        run_dir = wait_for_line(sim, "run folder:").split(":", 1)[1].strip()
        saved = tmp_path / "live.rrd"
        viewer = start("view", "--connect", endpoint, run_dir, "--save", str(saved))
        assert sim.wait(timeout=60) == 0
        stdout, stderr = viewer.communicate(timeout=60)
    finally:
        sim.kill()
    assert viewer.returncode == 0, stderr
    assert "run ended: completed" in stdout
    rows: dict[str, int] = {}
    for chunk in rr.chunk.RrdReader(saved).stream():
        if not chunk.is_static:
            rows[chunk.entity_path] = rows.get(chunk.entity_path, 0) + chunk.num_rows
    # Paced at the wall clock: at most the newest state 20 times a second (FPS) and the newest
    # scan of the 10 a second, and every IMU sample (small ones are all shown). It attached
    # late, and later when the machine is loaded, so the rates are judged over the span it saw
    # (its IMU samples). At nice 10 it yields to the run: on a loaded machine it drew fewer
    # frames (CI: 24 states in 4.3 s; a CI rehearsal: one in 1.9 s, its IMU rows all there),
    # so below it only needs to have drawn each kind: how fast is the benchmark's question.
    seen_s = rows["/series/imu_accel/ego.imu"] / 50.0
    assert 1.0 < seen_s <= 8.0
    assert 1 <= rows["/world/bodies/boat-monohull"] <= 8 * 20 + 1
    assert 1 <= rows["/world/vessels/ego/lidar"] <= 80
    assert rows["/metrics"] == 1  # read from the run folder once the recorder wrote it


def test_a_view_of_a_finished_run_says_nothing_answers_and_how_to_replay(tmp_path: Path) -> None:
    """A view that comes after the end, nothing listening, waited for an End forever (a view
    that lost its run after attaching: tests/services/viewer/test_ending.py)."""
    endpoint = f"tcp/127.0.0.1:{free_port()}"
    out = tmp_path / "runs"
    done = catabot("run", str(scenario_file(tmp_path, _scenario(1.0))), "--out", str(out),
                   "--quiet", "--listen", endpoint)  # fmt: skip
    assert done.returncode == 0, done.stderr
    run_dir = str(only_run_dir(out))
    late = catabot("view", "--connect", endpoint, run_dir, "--save", str(tmp_path / "a.rrd"))
    assert late.returncode == 2 and "Traceback" not in late.stderr
    assert f"nothing answers at ['{endpoint}']; the run in {run_dir} has ended (completed): " in (
        late.stderr
    )
    assert (tmp_path / "a.rrd").is_file()  # what it drew (nothing) is still saved


def test_a_run_with_the_view_records_the_same_bytes(tmp_path: Path) -> None:
    scenario = scenario_file(tmp_path, _scenario(2.0))
    recorded = []
    for tag, extra in (("plain", ()), ("viewed", ("--view", "web"))):
        out = tmp_path / tag
        out.mkdir()
        result = catabot("run", str(scenario), "--out", str(out), "--quiet", *extra)
        assert result.returncode == 0, result.stderr
        run = only_run_dir(out)
        recorded.append(files_of(run))
        if extra:
            assert "rerun web viewer: http://127.0.0.1:" in result.stdout
            assert "run ended: completed" in (run / "log" / "viewer.log").read_text()
    assert recorded[0] == recorded[1] and "run.mcap" in recorded[0]


def test_view_finds_the_running_world_without_a_source(tmp_path: Path) -> None:
    """A Gym episode's run has no folder to name: `catabot view --connect` alone asks the
    endpoint for its world (it used the default scenario's, matched nothing, and hung)."""
    endpoint = f"tcp/127.0.0.1:{free_port()}"
    scenario = scenario_file(tmp_path, _scenario(8.0) | {"name": "unnamed"})  # a late view
    sim = start("run", str(scenario), "--out", str(tmp_path / "runs"), "--quiet", "--listen",
                endpoint, "--realtime", "1.0")  # fmt: skip
    try:
        wait_for_line(sim, "run folder:")
        viewer = start("view", "--connect", endpoint, "--save", str(tmp_path / "live.rrd"))
        assert sim.wait(timeout=60) == 0
        stdout, stderr = viewer.communicate(timeout=60)
    finally:
        sim.kill()
    assert viewer.returncode == 0, stderr
    assert "run ended: completed" in stdout and "shown: nothing" not in stdout, stdout
