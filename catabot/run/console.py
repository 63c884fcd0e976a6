"""The command line's console outlives where it writes to.

A terminal closed under `catabot run` (SIGHUP, then every write fails with EIO) killed the
launcher at its next progress line, before it wrote `log/run.json`; `catabot get | head -1`
ended on "Broken pipe". Once a write fails, the stream goes to /dev/null instead (Python's
advice for SIGPIPE), so the command still finishes its work and its files; only the words
are lost, and there was nobody left to read them.
"""

from __future__ import annotations

import contextlib
import os
import sys
from collections.abc import Iterator
from typing import Any, TextIO, cast


class _Lasting:
    """A text stream whose writes cannot fail: the first OSError sends it to /dev/null."""

    def __init__(self, stream: TextIO) -> None:
        self._stream = stream
        self.gone = False

    def write(self, text: str) -> int:
        if not self.gone:
            try:
                return self._stream.write(text)
            except OSError:
                self._lose()
        return len(text)

    def flush(self) -> None:
        if not self.gone:
            try:
                self._stream.flush()
            except OSError:
                self._lose()

    def isatty(self) -> bool:
        return not self.gone and _isatty(self._stream)

    def __getattr__(self, name: str) -> Any:
        return getattr(self._stream, name)

    def _lose(self) -> None:
        """Point the file descriptor at /dev/null too: what is left in the stream's buffer
        (and Python's flush at exit) then goes nowhere instead of raising again."""
        self.gone = True
        with contextlib.suppress(OSError, ValueError, AttributeError):
            null = os.open(os.devnull, os.O_WRONLY)
            os.dup2(null, self._stream.fileno())
            os.close(null)


def _isatty(stream: TextIO) -> bool:
    try:
        return stream.isatty()
    except (OSError, ValueError):
        return False


@contextlib.contextmanager
def lasting() -> Iterator[None]:
    """sys.stdout and sys.stderr that outlive their terminal or pipe, for the block."""
    saved = sys.stdout, sys.stderr
    sys.stdout, sys.stderr = cast(TextIO, _Lasting(saved[0])), cast(TextIO, _Lasting(saved[1]))
    try:
        yield
    finally:
        sys.stdout, sys.stderr = saved
