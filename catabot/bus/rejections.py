"""Inputs a process refused, logged without flooding and counted for the run's summary.

A buggy client can send a bad sample a hundred times a second: each (key, reason) is logged
at most once a second with the count since the last line, except that each of its first
`FIRST_DETAILS` different details is logged when first met (a surge out of range and a yaw
rate out of range are both "invalid content": the second one's words were lost); totals are
kept per reason, and `write` leaves them in `log/<process>.rejected.json` for `catabot run`'s
summary.
"""

from __future__ import annotations

import json
import logging
import time
from collections import Counter
from pathlib import Path

REPORT = ": refused a sample on "  # the log line `report_of` reads back
FIRST_DETAILS = 8  # per (key, reason): bounded, whatever a hostile client varies


class Rejected(Exception):
    """A sample refused where it arrived: `reason` is short (counted), `detail` is logged."""

    def __init__(self, reason: str, detail: str = "") -> None:
        super().__init__(f"{reason}: {detail}" if detail else reason)
        self.reason, self.detail = reason, detail


class Rejections:
    def __init__(self, log: logging.Logger, who: str, *, every_s: float = 1.0) -> None:
        self.log, self.who, self.every_s = log, who, every_s
        self.totals: Counter[str] = Counter()
        self._since: Counter[tuple[str, str]] = Counter()
        self._last: dict[tuple[str, str], float] = {}
        self._details: dict[tuple[str, str], set[str]] = {}

    def add(self, key: str, rejected: Rejected, *, count: int = 1) -> None:
        """`count`: samples this refusal stands for (a flood's, counted where it arrived)."""
        self.totals[rejected.reason] += count
        item = (key, rejected.reason)
        self._since[item] += count
        now = time.monotonic()
        if self._new_detail(item, rejected.detail) or (
            now - self._last.get(item, -self.every_s) >= self.every_s
        ):
            count = self._since.pop(item)
            more = f" ({count} since the last report)" if count > 1 else ""
            self.log.warning("%s%s%s: %s%s", self.who, REPORT, key, rejected, more)
            self._last[item] = now

    def _new_detail(self, item: tuple[str, str], detail: str) -> bool:
        seen = self._details.setdefault(item, set())
        if detail in seen or len(seen) >= FIRST_DETAILS:
            return False
        seen.add(detail)
        return True

    def write(self, path: Path) -> None:
        """Totals by reason (nothing is written when nothing was refused)."""
        if self.totals:
            path.write_text(json.dumps(dict(sorted(self.totals.items())), indent=2) + "\n")


def report_of(line: str) -> tuple[str, str, str] | None:
    """(key, reason, detail) of a log line `Rejections.add` wrote, else None: `catabot run`
    echoes the first of each kind to the console (catabot/run/supervisor.py). Reasons never
    hold ": "; a key from a hostile client might, and then only this echo's grouping suffers."""
    _, found, rest = line.partition(REPORT)
    if not found:
        return None
    key, _, rest = rest.rstrip("\n").partition(": ")
    reason, _, detail = rest.partition(": ")
    if detail.endswith(" since the last report)"):
        detail = detail.rsplit(" (", 1)[0]
    return key, reason, detail
