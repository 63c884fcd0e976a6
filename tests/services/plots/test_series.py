"""Derived series of the plots: the closest approach of the scenario's vessels to any other,
tick by tick."""

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
    got = closest_approach(xy, [0, 2])  # the first and third are the scenario's own
    a_b = np.abs(100.0 - t * 0.25)
    b_c = np.hypot(50.0 - (100.0 - t * 0.25), 30.0)
    expected = np.minimum(np.minimum(a_b, b_c), np.hypot(50.0, 30.0))
    assert np.allclose(got, expected) and got[400] == 0.0
    alone = closest_approach(xy, [0])  # B against C is no scenario vessel's: left out
    assert np.allclose(alone, np.minimum(a_b, np.hypot(50.0, 30.0)))


def test_traffic_boats_against_each_other_are_left_out() -> None:
    """A swarm researcher's curve dipped to 6.1 m where two traffic boats met, below the
    marked minimum and metrics.json's closest approach."""
    xy = np.array([[[0.0, 0.0], [100.0, 0.0], [106.0, 0.0]]])  # own, then two boats 6 m apart
    assert closest_approach(xy, [0])[0] == 100.0


def test_one_vessel_has_no_closest_approach() -> None:
    assert np.isinf(closest_approach(np.zeros((5, 1, 2)), [0])).all()
