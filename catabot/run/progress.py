"""The launcher's progress line: simulated time, ticks per second, real-time factor."""

from __future__ import annotations

import sys
import time
from collections.abc import Mapping
from typing import Any


class ProgressBar:
    def __init__(self, total_ns: int, *, enabled: bool = True, width: int = 28) -> None:
        self.total_ns, self.enabled, self.width = total_ns, enabled, width
        self.tty = sys.stderr.isatty()
        self.last_print = 0.0
        self.shown = False

    def line(self, event: Mapping[str, Any]) -> str:
        frac = min(event["stamp_ns"] / self.total_ns, 1.0)
        filled = int(frac * self.width)
        bar = "#" * filled + "-" * (self.width - filled)
        return (
            f"[{bar}] {event['stamp_ns'] / 1e9:8.2f}/{self.total_ns / 1e9:.2f} s sim"
            f" | {event['ticks_per_s']:8.0f} ticks/s | RTF {event['realtime_factor']:7.2f}x"
        )

    def update(self, event: Mapping[str, Any]) -> None:
        if not self.enabled:
            return
        now = time.monotonic()
        if self.tty:
            sys.stderr.write("\r" + self.line(event))
            sys.stderr.flush()
            self.shown = True
        elif now - self.last_print >= 2.0 or event["stamp_ns"] >= self.total_ns:
            sys.stderr.write(self.line(event) + "\n")
            self.last_print = now

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
