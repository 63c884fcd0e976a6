"""The held web viewer (catabot/run/companions.py) ends on SIGTERM and SIGHUP as on Ctrl-C:
it runs in its own session, and a signal to the launcher left it serving, orphaned."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import threading
from pathlib import Path

import pytest

from catabot.run.companions import Viewer


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGHUP])
def test_a_signal_ends_the_hold_and_stops_the_viewer(tmp_path: Path, sig: signal.Signals) -> None:
    serving = subprocess.Popen(
        [sys.executable, "-c", "import time; time.sleep(60)"], text=True, start_new_session=True
    )
    viewer = Viewer(serving, "http://127.0.0.1:1/", tmp_path / "ready")
    before = signal.getsignal(sig)
    threading.Timer(0.5, os.kill, (os.getpid(), sig)).start()
    viewer.hold()
    assert serving.poll() is not None  # stopped, not left serving
    assert signal.getsignal(sig) == before  # the launcher's own handling is back


def test_a_viewer_that_did_not_start_is_told_in_its_own_words(tmp_path: Path) -> None:
    """`catabot run --view native` with no display said only "see log/viewer.log"."""
    proc = subprocess.Popen([sys.executable, "-c", "pass"], text=True)
    proc.wait()
    viewer = Viewer(proc, None, tmp_path / "log" / "viewer.ready")
    assert viewer.why() == f"see {tmp_path / 'log' / 'viewer.log'}"  # no log yet
    (tmp_path / "log").mkdir()
    (tmp_path / "log" / "viewer.log").write_text("INFO x\ncatabot view: no display here\n")
    assert viewer.why() == "no display here"
