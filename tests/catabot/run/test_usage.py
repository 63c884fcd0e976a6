"""Peak memory is each process's own: a process started from a big one does not report the
big one's peak (getrusage's ru_maxrss survives fork and exec; VmHWM does not)."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

from catabot.run.usage import _kib_fields, memory_mb, peak_rss_mb, read_usage, write_usage

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


def test_proportional_and_anonymous_memory_count_a_shared_library_once() -> None:
    """A big private allocation shows in all three figures; PSS and anonymous memory are
    read as the process is now, so they do not exceed the peak. PSS also holds this
    process's share of shared file pages, which falls meanwhile when another process (a
    sibling test worker) maps the same libraries: CI saw 176 MB for the 200 MB block."""
    before = memory_mb()
    block = bytearray(200 * 2**20)  # touched (zeroed) pages of this process's own
    after = memory_mb()
    assert set(after) == {"peak_rss_mb", "pss_mb", "anon_mb"}
    assert after["anon_mb"] - before["anon_mb"] > 190.0
    assert after["pss_mb"] - before["pss_mb"] > 140.0
    assert after["anon_mb"] < after["pss_mb"] <= after["peak_rss_mb"]
    del block


def test_smaps_rollup_lines_are_read_by_name() -> None:
    text = "55e0-7ffd ---p 00000000 00:00 0  [rollup]\nRss:  2048 kB\nPss_Anon:  12 kB\n"
    assert dict(_kib_fields(text)) == {"Rss": 2048, "Pss_Anon": 12}


def test_usage_files_keep_every_memory_figure(tmp_path: Path) -> None:
    write_usage("sensors", tmp_path, 0.5)
    for field in ("peak_rss_mb", "pss_mb", "anon_mb"):
        assert read_usage(tmp_path, ["sensors"], field)["sensors"] > 1.0
