"""Advice lines are found in a service's log by `catabot run` and nothing else is."""

from __future__ import annotations

import logging

import pytest

from catabot.run.advice import advice_of, advise


def test_an_advised_line_reads_back_and_others_do_not(caplog: pytest.LogCaptureFixture) -> None:
    with caplog.at_level(logging.INFO):
        advise(logging.getLogger("physics.reach"), "ego: too fast")
    record = caplog.records[0]
    line = f"2026-12-06 10:00:00,000 {record.name} {record.levelname} {record.getMessage()}\n"
    assert advice_of(line) == "ego: too fast"
    assert advice_of("2026 physics INFO advice: not at warning level") is None
    assert advice_of("2026 physics WARNING physics: refused a sample on k: bad") is None
