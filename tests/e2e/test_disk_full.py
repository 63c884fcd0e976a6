"""A disk that fills up during a run: the error names the file and the process, no CSV row is
torn, the MCAP reads to its last complete record, and the launcher still reports the end."""

from __future__ import annotations

import contextlib
import subprocess
from collections.abc import Iterator
from pathlib import Path

import pytest
from conftest import basic_scenario, catabot, csv_rows, only_run_dir, scenario_file

from services.recorder.mcap_read import read_mcap_messages


@pytest.fixture
def small_disk(tmp_path: Path) -> Iterator[Path]:
    """A 3 MiB tmpfs (skips where mounting is not allowed)."""
    where = tmp_path / "small"
    where.mkdir()
    mount = subprocess.run(
        ["mount", "-t", "tmpfs", "-o", "size=3m", "tmpfs", str(where)], capture_output=True
    )
    if mount.returncode != 0:
        pytest.skip(f"cannot mount a tmpfs here: {mount.stderr.decode().strip()}")
    try:
        yield where
    finally:
        with contextlib.suppress(Exception):
            subprocess.run(["umount", "-l", str(where)], check=False)


def test_a_full_disk_is_named_and_leaves_readable_files(tmp_path: Path, small_disk: Path) -> None:
    data = basic_scenario("full", duration_s=20.0)
    lidar = {"name": "lidar", "type": "lidar", "rate_hz": 10.0}
    data["vessels"][0]["sensors"] = [{"name": "imu", "type": "imu", "rate_hz": 100.0}, lidar]
    result = catabot("run", str(scenario_file(tmp_path, data)), "--out", str(small_disk), "--quiet")
    assert result.returncode == 1, result.stderr
    failure = next(ln for ln in result.stderr.splitlines() if ln.startswith("run failed:"))
    assert failure.startswith("run failed: recorder: cannot write "), failure
    assert "No space left on device" in failure
    assert "Traceback" not in result.stderr
    run = only_run_dir(small_disk)
    for csv in run.glob("*.csv"):
        rows = csv_rows(csv)
        assert rows and all(len(r) == len(rows[0]) for r in rows), f"{csv.name}: a torn row"
    messages = read_mcap_messages(run / "run.mcap")
    assert len(messages) > 10  # every complete record up to where the disk filled
    assert (run / "run.mcap").stat().st_size <= 3 * 2**20
