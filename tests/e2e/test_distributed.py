"""A host per process (network namespaces on one switch, a router): the same bytes as one
machine; a cut cable or a host that dies is named within 2 s and the recording stays whole."""

from __future__ import annotations

import csv
import os
import shutil
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest
from conftest import REPO, basic_scenario, catabot, files_of, only_run_dir, scenario_file
from mcap.reader import make_reader

from catabot.bus.participant import VANISHED

DETECT_S = 2.0  # the link lease (1.5 s) and the token's way to the conductor
SLACK_S = 1.0  # a loaded CI machine


def _netns_available() -> bool:
    if os.geteuid() != 0 or shutil.which("ip") is None:
        return False
    # Each pytest worker probes a name of its own: two workers adding one name at once made
    # one of them skip every test here.
    name = f"cbprobe{os.getpid()}"
    probe = subprocess.run(["ip", "netns", "add", name], capture_output=True)
    subprocess.run(["ip", "netns", "del", name], capture_output=True)
    return probe.returncode == 0


pytestmark = pytest.mark.skipif(not _netns_available(), reason="needs root and ip netns")


def hosts(scenario: Path, out: Path, *fault: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        ["bash", str(REPO / "deploy" / "hosts.sh"), str(scenario), str(out), *fault],
        capture_output=True,
        text=True,
        timeout=120,
        cwd=REPO,
        env={**os.environ, "PYTHON": sys.executable},
    )


def traffic_scenario(name: str, **top: Any) -> dict[str, Any]:
    data = basic_scenario(name, traffic={"count": 3}, **top)
    data["vessels"][0]["sensors"] = [{"name": "gps", "type": "gps", "rate_hz": 10.0}]
    return data


def test_a_host_per_process_records_the_same_bytes_as_one_machine(
    tmp_path: Path, out: Path
) -> None:
    scenario = scenario_file(tmp_path, traffic_scenario("hosts", duration_s=3.0))
    local = catabot("run", str(scenario), "--out", str(out), "--quiet")
    assert local.returncode == 0, local.stderr
    remote = tmp_path / "remote"
    result = hosts(scenario, remote)
    assert result.returncode == 0, result.stdout + result.stderr
    assert '"error": ""' in result.stdout
    laid_out = [line.split()[1] for line in result.stdout.splitlines() if line.startswith("host ")]
    assert laid_out == ["router", "conductor", "physics", "sensors", "traffic", "recorder"]
    assert files_of(remote) == files_of(only_run_dir(out))


def _times(stdout: str) -> tuple[float, float]:
    lines = stdout.splitlines()
    stamp = {w[0]: float(w[-1]) for w in map(str.split, lines) if w[0] in ("fault", "conductor")}
    return stamp["fault"], stamp["conductor"]


def _whole(run: Path) -> int:
    """Every CSV row complete and every MCAP record readable; the last recorded tick."""
    last = -1
    for path in run.glob("*.csv"):
        rows = list(csv.reader(path.open()))
        assert {len(row) for row in rows} == {len(rows[0])}, path.name
        last = max(last, max((int(row[1]) for row in rows[1:]), default=-1))
    with (run / "run.mcap").open("rb") as f:
        assert sum(1 for _ in make_reader(f).iter_messages()) > 0
    return last


@pytest.mark.parametrize(("fault", "victim"), [("--cut", "physics"), ("--kill", "sensors")])
def test_a_lost_host_is_named_within_the_lease_and_the_recording_is_whole(
    tmp_path: Path, fault: str, victim: str
) -> None:
    paced = traffic_scenario(f"lost{victim}", duration_s=20.0, clock={"realtime_factor": 1.0})
    scenario = scenario_file(tmp_path, paced)
    run = tmp_path / "run"
    result = hosts(scenario, run, fault, victim, "1.5")
    assert result.returncode == 1, result.stdout + result.stderr
    assert f"participant '{victim}' left the run" in result.stdout
    faulted, ended = _times(result.stdout)
    assert ended - faulted <= DETECT_S + SLACK_S, ended - faulted
    assert "did not end" not in result.stderr  # every survivor flushed and exited by itself
    assert 100 < _whole(run) < 2000  # ticks from before the fault, none after the run's end


def test_a_recorder_cut_off_from_the_clock_still_closes_its_files(tmp_path: Path) -> None:
    """Its run.mcap had no footer and metrics.json was missing: the recorder exited on
    losing the conductor without closing them."""
    paced = traffic_scenario("cutrec", duration_s=20.0, clock={"realtime_factor": 1.0})
    run = tmp_path / "run"
    result = hosts(scenario_file(tmp_path, paced), run, "--cut", "recorder", "1.5")
    assert result.returncode == 1, result.stdout + result.stderr
    assert "participant 'recorder' left the run" in result.stdout
    assert 100 < _whole(run) < 2000
    with (run / "run.mcap").open("rb") as f:
        assert make_reader(f).get_summary() is not None  # the footer and summary written
    assert (run / "metrics.json").is_file()
    log = next(run.glob("**/recorder.log")).read_text()
    assert f"{VANISHED} (its files end at tick" in log


def test_a_fault_on_no_service_of_the_scenario_is_refused_leaving_no_folder(
    tmp_path: Path,
) -> None:
    """`--cut conductor 4` was refused after the output folder was made."""
    out = tmp_path / "out"
    refused = hosts(scenario_file(tmp_path, basic_scenario("nope")), out, "--cut", "conductor", "4")
    assert refused.returncode == 2 and "no service conductor in this scenario" in refused.stderr
    assert not out.exists()
