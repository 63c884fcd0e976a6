"""Two hosts (network namespaces, a veth link, a router) record the same bytes as one machine."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from conftest import REPO, basic_scenario, catabot, files_of, only_run_dir, scenario_file


def _netns_available() -> bool:
    if os.geteuid() != 0 or shutil.which("ip") is None:
        return False
    probe = subprocess.run(["ip", "netns", "add", "cbprobe"], capture_output=True)
    subprocess.run(["ip", "netns", "del", "cbprobe"], capture_output=True)
    return probe.returncode == 0


@pytest.mark.skipif(not _netns_available(), reason="needs root and ip netns")
def test_two_hosts_record_the_same_bytes_as_one(tmp_path: Path, out: Path) -> None:
    data = basic_scenario("twohosts", duration_s=3.0)
    data["vessels"][0]["sensors"] = [{"name": "gps", "type": "gps", "rate_hz": 10.0}]
    scenario = scenario_file(tmp_path, data)
    local = catabot("run", str(scenario), "--out", str(out), "--quiet")
    assert local.returncode == 0, local.stderr
    remote = tmp_path / "remote"
    result = subprocess.run(
        ["bash", str(REPO / "deploy" / "two-hosts.sh"), str(scenario), str(remote)],
        capture_output=True,
        text=True,
        timeout=120,
        cwd=REPO,
        env={**os.environ, "PYTHON": sys.executable},
    )
    assert result.returncode == 0, result.stdout + result.stderr
    assert '"error": ""' in result.stdout
    assert files_of(remote) == files_of(only_run_dir(out))
