"""The command line's console outlives its terminal or pipe (catabot/run/console.py)."""

from __future__ import annotations

import errno
import io
import sys

import pytest

from catabot.run import cli
from catabot.run.cli import main
from catabot.run.console import _Lasting


class _HungUp(io.StringIO):
    def write(self, text: str) -> int:
        raise OSError(errno.EIO, "Input/output error")


class _Closed(io.StringIO):
    def write(self, text: str) -> int:
        raise BrokenPipeError(errno.EPIPE, "Broken pipe")

    def fileno(self) -> int:
        raise io.UnsupportedOperation("no descriptor")


def test_a_failed_write_is_dropped_and_so_is_every_later_one() -> None:
    stream = _Lasting(_HungUp())
    assert stream.write("progress") == len("progress")
    assert stream.gone and not stream.isatty()
    assert stream.write("summary") == len("summary")
    stream.flush()


def test_a_reader_that_leaves_early_ends_no_command_with_an_error(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """`catabot get | head -1`: the lines after the first met a closed pipe, and the command
    said "catabot get: Broken pipe" and failed (exit 2)."""
    monkeypatch.setattr(sys, "stdout", _Closed())
    assert main(["scenario", "schema"]) == 0


def test_a_service_keeps_its_own_stdout(monkeypatch: pytest.MonkeyPatch) -> None:
    """A conductor ends its run once nobody reads its stdout (its launcher gone): a stream
    that cannot fail would have kept it ticking, an orphan."""
    seen: list[object] = []
    monkeypatch.setattr(cli, "_command", lambda argv: seen.append(sys.stdout) or 0)
    assert cli.main(["service", "conductor"]) == 0 and cli.main(["get"]) == 0
    assert seen[0] is sys.stdout and isinstance(seen[1], _Lasting)
