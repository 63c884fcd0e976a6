"""Derived series of the plots: the closest approach between any two vessels, tick by tick."""

from __future__ import annotations

import numpy as np

from services.plots.series import closest_approach


def test_closest_approach_of_every_pair_at_every_tick() -> None:
    t = np.arange(600)  # more ticks than one block of the bounded computation
    xy = np.stack([
        np.stack([t * 0.0, t * 0.0], axis=1),  # still
        np.stack([100.0 - t * 0.25, t * 0.0], axis=1),  # closing in along x
        np.stack([t * 0.0 + 50.0, t * 0.0 + 30.0], axis=1),  # still, 30 m off the line
    ], axis=1)  # fmt: skip
    got = closest_approach(xy)
    a_b = np.abs(100.0 - t * 0.25)
    b_c = np.hypot(50.0 - (100.0 - t * 0.25), 30.0)
    expected = np.minimum(np.minimum(a_b, b_c), np.hypot(50.0, 30.0))
    assert np.allclose(got, expected) and got[400] == 0.0


def test_one_vessel_has_no_closest_approach() -> None:
    assert np.isinf(closest_approach(np.zeros((5, 1, 2)))).all()
