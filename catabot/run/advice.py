"""Advice: what a service tells the user about a run that goes on as asked.

Not a refusal (the input was taken) and not a fault (nothing failed), but something the
user would otherwise find only by reading the recording: a twist set-point beyond what a
vessel's thrusters can hold settles short of it. The service logs it once; `catabot run`
echoes it on the console (catabot/run/supervisor.py), as it echoes refusals.
"""

from __future__ import annotations

import logging

MARK = " WARNING advice: "  # how `advice_of` finds the line: the level, then this word
TOLD = " INFO told: "  # news for the console that is no warning: a setting changed


def advise(log: logging.Logger, text: str) -> None:
    log.warning("advice: %s", text)


def tell(log: logging.Logger, text: str) -> None:
    """What the person at the run's console would want to see happen (a `catabot set` from
    another terminal: who else would say so?), echoed as advice is."""
    log.info("told: %s", text)


def advice_of(line: str) -> str | None:
    """The text of a line `advise` or `tell` logged (one line: the formatter's), else None."""
    for mark in (MARK, TOLD):
        _, found, text = line.partition(mark)
        if found:
            return text.strip()
    return None
