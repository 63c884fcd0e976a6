"""The launcher's progress line: simulated time, ticks per second, real-time factor."""

from __future__ import annotations

import os
import sys
import time
from collections.abc import Mapping
from typing import Any

MIN_BAR = 8  # the narrowest bar kept before the line is cut


class ProgressBar:
    def __init__(self, total_ns: int, *, enabled: bool = True, width: int = 28) -> None:
        self.total_ns, self.enabled, self.width = total_ns, enabled, width
        self.tty = sys.stderr.isatty()
        self.last_print = 0.0
        self.shown = False

    def line(self, event: Mapping[str, Any], *, width: int | None = None) -> str:
        width = self.width if width is None else width
        frac = min(event["stamp_ns"] / self.total_ns, 1.0)
        filled = int(frac * width)
        bar = "#" * filled + "-" * (width - filled)
        return (
            f"[{bar}] {event['stamp_ns'] / 1e9:8.2f}/{self.total_ns / 1e9:.2f} s sim"
            f" | {event['ticks_per_s']:8.0f} ticks/s | RTF {event['realtime_factor']:7.2f}x"
        )

    def update(self, event: Mapping[str, Any]) -> None:
        if not self.enabled:
            return
        now = time.monotonic()
        if self.tty:
            sys.stderr.write("\r" + self.fitted(event, _columns()) + "\033[K")
            sys.stderr.flush()
            self.shown = True
        elif now - self.last_print >= 2.0 or event["stamp_ns"] >= self.total_ns:
            sys.stderr.write(self.line(event) + "\n")
            self.last_print = now

    def fitted(self, event: Mapping[str, Any], columns: int) -> str:
        """The line within a terminal's width: the bar gives way first, then the line is cut.
        A line that wrapped (85-86 characters at 80 columns) left a copy at every update, as `\r`
        goes back to the start of the last row only."""
        room = columns - 1  # the last column would wrap on some terminals
        text = self.line(event)
        if len(text) > room:
            text = self.line(event, width=max(self.width - (len(text) - room), MIN_BAR))
        return text[:room]

    def note(self, text: str) -> None:
        """A line for the person at the console while the run goes (a refused command),
        on its own line above the bar; shown with --quiet too."""
        if self.enabled and self.tty and self.shown:
            sys.stderr.write("\r\033[K")  # the bar is redrawn by the next update
        sys.stderr.write(f"{text}\n")
        sys.stderr.flush()

    def close(self) -> None:
        if self.enabled and self.tty and self.shown:
            sys.stderr.write("\n")


def _columns() -> int:
    """The width of the terminal stderr writes to (80 where it cannot be told)."""
    try:
        return os.get_terminal_size(sys.stderr.fileno()).columns or 80
    except (OSError, ValueError):
        return 80


class PlanningProgress:
    """`(k, n)` from a long traffic plan, shown at most once a second after the first (a plan
    of hundreds of boats with many waypoints takes a while, and silence looks like a hang)."""

    def __init__(self, *, after_s: float = 1.0) -> None:
        self.start = time.monotonic()
        self.next = self.start + after_s

    def __call__(self, done: int, total: int) -> None:
        now = time.monotonic()
        if now >= self.next or (done == total and self.next > self.start + 1.0):
            sys.stderr.write(f"planning traffic: {done}/{total} boats ({now - self.start:.0f} s)\n")
            sys.stderr.flush()
            self.next = now + 1.0
