"""Episodes: one per contact, merged across short gaps, with the least value and its time."""

from __future__ import annotations

import numpy as np

from services.recorder.episodes import Episode, Episodes


def test_episodes_start_end_merge_and_least() -> None:
    eps = Episodes((2,), gap_ns=20)
    holds = [(1, 0), (1, 0), (0, 0), (1, 1), (0, 1), (0, 0), (0, 0), (0, 0), (1, 0)]
    values = [5.0, 3.0, 1.0, 4.0, 2.0, 0.0, 0.0, 0.0, 7.0]
    for k, (h, v) in enumerate(zip(holds, values, strict=True)):
        eps.update(np.array(h, dtype=bool), 10 * k, np.array([v, v]))
    assert eps.all() == [
        Episode((0,), 0, 30, 3.0, 10),  # the one-tick gap at 20 is bridged; 1.0 was outside
        Episode((1,), 30, 40, 2.0, 40),
        Episode((0,), 80, None, 7.0, 80),  # still going at the end
    ]


def test_nothing_held_nothing_reported() -> None:
    eps = Episodes((3, 4), gap_ns=0)
    for k in range(5):
        eps.update(np.zeros((3, 4), dtype=bool), k)
    assert eps.all() == []
