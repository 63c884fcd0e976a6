"""`catabot run`'s `zenoh:` line comes once its endpoint takes connections: printed before
the conductor listened, a script that connected on reading it was refused (1.7 s early)."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

from catabot.bus.session import free_port, port_open


def test_the_zenoh_line_comes_once_clients_can_connect(tmp_path: Path) -> None:
    data = {
        "name": "announced", "duration_s": 1.0, "clock": {"start_timeout_s": 3.0},
        "vessels": [{"id": "ego", "controller": {"participant": "stack", "rate_hz": 10.0}}],
    }  # fmt: skip
    path = tmp_path / "announced.json"
    path.write_text(json.dumps(data))
    endpoint = f"tcp/127.0.0.1:{free_port()}"
    argv = ["run", str(path), "--quiet", "--out", str(tmp_path / "runs"), "--listen", endpoint]
    proc = subprocess.Popen(
        [sys.executable, "-m", "catabot", *argv], stdout=subprocess.PIPE, text=True
    )
    assert proc.stdout is not None
    try:
        first = proc.stdout.readline()
        assert first.startswith("run folder: "), first
        line = proc.stdout.readline()
        assert line.startswith(f"zenoh: clients connect to {endpoint} (world 'announced'"), line
        assert port_open(endpoint, timeout_s=1.0) == ""
    finally:
        proc.communicate(timeout=120)
    assert proc.returncode == 1  # the stack it waited for never came
