"""`catabot view`'s desktop viewer (services/viewer/cli.py): started from this Python's own
environment, and refused in one line where no display is."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any

import pytest
import rerun as rr

from services.viewer import cli


def test_no_display_is_one_clear_line(monkeypatch: pytest.MonkeyPatch) -> None:
    """rerun's viewer died without a display and `catabot view` hung past SIGTERM."""
    monkeypatch.setattr(sys, "platform", "linux")
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    with pytest.raises(cli.ViewerError, match=r"no display here .* use --web"):
        cli._spawn(rr.RecordingStream("test"), None)


def test_the_viewer_is_this_environments_rerun(monkeypatch: pytest.MonkeyPatch) -> None:
    """A venv not activated has its `rerun` off PATH: rerun's own lookup failed with a
    traceback telling to pip install what was installed."""
    monkeypatch.setenv("DISPLAY", ":0")
    monkeypatch.setenv("PATH", "/usr/bin:/bin")
    spawned: dict[str, Any] = {}
    monkeypatch.setattr(rr, "spawn", lambda **kwargs: spawned.update(kwargs))
    cli._spawn(rr.RecordingStream("test"), None)
    beside = Path(sys.executable).with_name("rerun")
    assert beside.is_file() and spawned["executable_path"] == str(beside)


def test_a_viewer_that_cannot_start_is_one_clear_line(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("DISPLAY", ":0")

    def fails(**_: Any) -> None:
        raise RuntimeError("Failed to find Rerun Viewer executable in PATH.")

    monkeypatch.setattr(rr, "spawn", fails)
    with pytest.raises(cli.ViewerError, match=r"cannot start the rerun viewer \(Failed .*--web"):
        cli._spawn(rr.RecordingStream("test"), None)
