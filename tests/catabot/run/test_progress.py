"""The progress line fits its terminal: at 80 columns the 85-character line wrapped, and
every update left a copy behind (`\\r` goes back to the start of the last row only)."""

from __future__ import annotations

from catabot.run.progress import MIN_BAR, ProgressBar

EVENT = {"stamp_ns": 62_000_000_000, "ticks_per_s": 1004.0, "realtime_factor": 2.39}


def test_a_wide_terminal_gets_the_whole_line() -> None:
    bar = ProgressBar(120_000_000_000)
    assert bar.fitted(EVENT, 200) == bar.line(EVENT) and len(bar.line(EVENT)) == 86


def test_at_80_columns_the_bar_narrows_and_every_figure_stays() -> None:
    line = ProgressBar(120_000_000_000).fitted(EVENT, 80)
    assert len(line) == 79 and line.endswith("| RTF    2.39x")
    assert line.startswith("[##########-----------]    62.00/120.00 s sim")


def test_narrower_still_the_line_is_cut_after_the_narrowest_bar() -> None:
    line = ProgressBar(120_000_000_000).fitted(EVENT, 40)
    assert len(line) == 39 and line.startswith("[" + "#" * 4 + "-" * (MIN_BAR - 4) + "]")
