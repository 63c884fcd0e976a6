"""Peak memory is each process's own: a process started from a big one does not report the
big one's peak (getrusage's ru_maxrss survives fork and exec; VmHWM does not)."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

from catabot.run.usage import peak_rss_mb, read_usage, write_usage

PARENT = """
import json, resource, subprocess, sys
from catabot.run.usage import peak_rss_mb
block = bytearray(400 * 2**20)  # 400 MB, touched
child = subprocess.run([sys.executable, "-c",
    "import json, resource; from catabot.run.usage import peak_rss_mb; "
    "print(json.dumps([peak_rss_mb(), resource.getrusage(resource.RUSAGE_SELF).ru_maxrss]))"],
    capture_output=True, text=True, check=True)
print(json.dumps({"parent": peak_rss_mb(), "child": json.loads(child.stdout)}))
"""


def test_a_child_of_a_big_process_reports_its_own_peak() -> None:
    out = subprocess.run(
        [sys.executable, "-c", PARENT], capture_output=True, text=True, check=True
    ).stdout
    seen = json.loads(out)
    own, inherited_kib = seen["child"]
    assert seen["parent"] > 400.0
    assert own < 200.0, "the child's figure must not be its parent's"
    assert own < inherited_kib / 1024.0  # what ru_maxrss would have reported


def test_usage_files_round_trip(tmp_path: Path) -> None:
    write_usage("physics", tmp_path, 1.25)
    assert read_usage(tmp_path, ["physics", "sensors"], "cpu_s") == {"physics": 1.25}
    assert 10.0 < read_usage(tmp_path, ["physics"], "peak_rss_mb")["physics"] <= peak_rss_mb()
