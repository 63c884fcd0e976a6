"""`catabot run` on the bundled default scenario: run folder, CSV, MCAP, Archimedes."""

from __future__ import annotations

import contextlib
import json
import os
import time
from pathlib import Path

import pytest
from conftest import (
    basic_scenario,
    catabot,
    csv_rows,
    only_run_dir,
    scenario_file,
    service_pid,
    start,
    wait_for_line,
)

from catabot.config.vessel import load_vessel_model
from services.recorder.mcap_read import read_mcap_messages


def test_default_run_writes_run_folder_and_floats_at_archimedes_draft(out: Path) -> None:
    result = catabot("run", "--duration", "20", "--out", str(out), "--quiet")
    assert result.returncode == 0, result.stderr
    run = only_run_dir(out)
    assert "run folder:" in result.stdout and str(run) in result.stdout
    for name in (
        "scenario.json",
        "vessel.ego.state.csv",
        "run.mcap",
        "metrics.json",
        "log/physics.log",
    ):
        assert (run / name).is_file(), name
    rows = csv_rows(run / "vessel.ego.state.csv")
    header, data = rows[0], rows[1:]
    assert header[:3] == ["stamp_ns", "tick", "position_x[m]"]
    assert len(data) == 2001 and data[-1][0] == str(20 * 10**9)  # the start state, 2000 ticks
    assert data[0][:3] == ["0", "-1", "0.0"]  # where the vessel starts, at t = 0
    scenario = json.loads((run / "scenario.json").read_text())
    model = load_vessel_model(scenario["vessels"][0]["model"])
    rho = scenario["water"]["density_kg_m3"]
    area = sum(h.length_m * h.beam_m for h in model.hulls)
    keel = min(h.center_m[2] - (h.height_m or h.beam_m) / 2 for h in model.hulls)
    z = column(header, data, "position_z[m]", t_from=1.5, t_to=2.0)
    draft = -(sum(z) / len(z) + keel)
    assert abs(draft - model.mass_kg / (rho * area)) / (model.mass_kg / (rho * area)) < 0.02
    x = column(header, data, "position_x[m]", t_from=19.9, t_to=20.0)
    assert x[-1] > 10.0, "the scripted thrust must move the vessel"
    metrics = json.loads((run / "metrics.json").read_text())["vessels"]["ego"]
    assert abs(metrics["final_position_m"][0] - float(data[-1][2])) < 1e-9
    assert metrics["distance_m"] >= float(data[-1][2])
    messages = read_mcap_messages(run / "run.mcap")
    assert {"/ego/odom", "/tf"} <= {m.topic for m in messages}
    # the script's steps recorded as the commands they are, where an external one would be
    thrust = csv_rows(run / "vessel.ego.cmd.thrust.csv")
    assert thrust == [
        ["stamp_ns", "tick", "thrust_0", "thrust_1"],
        ["0", "0", "0.0", "0.0"],
        ["2000000000", "200", "0.8", "0.8"],
    ]  # fmt: skip (25 s: after the end)
    sent = [(m.log_time, list(m.decoded.data)) for m in messages if m.topic == "/ego/thrust"]
    assert sent == [(0, [0.0, 0.0]), (2 * 10**9, [0.8, 0.8])]
    usage = json.loads((run / "log" / "run.json").read_text())
    cpu, rss = usage["cpu_s"], usage["peak_rss_mb"]
    assert set(cpu) == {"physics", "sensors", "recorder"} and all(s > 0 for s in cpu.values())
    processes = {"launcher", "conductor", *cpu}
    assert set(rss) == processes | {"total"} and all(20 < rss[p] < 1000 for p in processes)
    assert rss["total"] == pytest.approx(sum(rss[p] for p in processes), abs=0.1)
    pss, anon = usage["pss_mb"], usage["anon_mb"]  # at the loop's end: at most the peak
    assert set(pss) == set(anon) == set(rss)
    assert all(0 < anon[p] < pss[p] <= rss[p] for p in processes)


def column(
    header: list[str], data: list[list[str]], name: str, *, t_from: float, t_to: float
) -> list[float]:
    i = header.index(name)
    return [float(r[i]) for r in data if t_from <= int(r[0]) / 1e9 <= t_to]


@pytest.mark.skipif(not hasattr(os, "SCHED_BATCH"), reason="SCHED_BATCH is Linux-only")
def test_services_step_under_batch_scheduling(tmp_path: Path, out: Path) -> None:
    """catabot/scheduling.py: every stepping service, and its Zenoh threads, is batch work."""
    data = basic_scenario(duration_s=3.0, clock={"realtime_factor": 1.0})
    proc = start("run", str(scenario_file(tmp_path, data)), "--out", str(out), "--quiet")
    wait_for_line(proc, "zenoh:")
    threads: list[int] = []
    for _ in range(100):  # until its Zenoh session has started its threads
        with contextlib.suppress(LookupError, FileNotFoundError):
            pid = service_pid(proc.pid, "services.physics")
            threads = [int(t) for t in os.listdir(f"/proc/{pid}/task")]
        if len(threads) >= 4:
            break
        time.sleep(0.05)
    policies = {os.sched_getscheduler(t) for t in threads}
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 0, err
    assert policies == {os.SCHED_BATCH}, policies
