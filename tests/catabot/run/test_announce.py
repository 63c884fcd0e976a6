"""What `catabot run` says before the clock starts (catabot/run/announce.py): its `zenoh:`
line once the endpoint takes connections (printed before the conductor listened, a script
that connected on reading it was refused, 1.7 s early), and the stack it waits for."""

from __future__ import annotations

import json
import re
import subprocess
import sys
from pathlib import Path

from catabot.bus.session import free_port, port_open


def _waiting(tmp: Path, *flags: str) -> list[str]:
    """`catabot run` of a scenario whose stack never comes (it gives up after 4 s)."""
    data = {
        "name": "waits", "duration_s": 1.0, "clock": {"start_timeout_s": 4.0},
        "vessels": [{"id": "ego", "controller": {"participant": "stack", "rate_hz": 10.0}}],
    }  # fmt: skip
    path = tmp / "waits.json"
    path.write_text(json.dumps(data))
    return [sys.executable, "-m", "catabot", "run", str(path), "--quiet", "--out",
            str(tmp / "runs"), *flags]  # fmt: skip


def test_the_zenoh_line_comes_once_clients_can_connect(tmp_path: Path) -> None:
    endpoint = f"tcp/127.0.0.1:{free_port()}"
    proc = subprocess.Popen(_waiting(tmp_path, "--listen", endpoint), stdout=subprocess.PIPE,
                            text=True)  # fmt: skip
    assert proc.stdout is not None
    try:
        first = proc.stdout.readline()
        assert first.startswith("run folder: "), first
        line = proc.stdout.readline()
        assert line.startswith(f"zenoh: clients connect to {endpoint} (world 'waits'"), line
        assert port_open(endpoint, timeout_s=1.0) == ""
    finally:
        proc.communicate(timeout=120)
    assert proc.returncode == 1  # the stack it waited for never came


def test_a_run_says_it_waits_for_a_stack_started_outside_it(tmp_path: Path) -> None:
    done = subprocess.run(_waiting(tmp_path), capture_output=True, text=True, timeout=120)
    assert "waiting for stack to join (started by you, connecting to tcp/" in done.stdout
    assert "the run gives up after 4 s" in done.stdout
    assert re.search(r"stack: e\.g\. python my_stack\.py --connect tcp/[\d.:]+ --participant "
                     r"stack --vessel ego\n", done.stdout), done.stdout  # fmt: skip
    assert done.returncode == 1  # under load a service may be late as well: named with it
    assert re.search(r"never joined within 4 s: (\w+, )*stack\n", done.stderr), done.stderr
    assert "0 ticks" in done.stdout and "ego:" not in done.stdout  # no metrics of 0 ticks
