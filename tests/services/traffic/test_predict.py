"""Where boats will be (services/traffic/predict.py): arcs against the circle's geometry,
and the sampled closest approach against two boats on known tracks."""

from __future__ import annotations

import math

import numpy as np

from services.traffic.predict import Movers, arc, closest, paths, sample_times

ONE = np.ones(1)  # a boat's size: unused by the geometry here


def test_an_arc_is_the_circle_the_boat_turns_on() -> None:
    rate, speed = 0.4, 5.0  # radius 12.5 m, half a turn in pi / 0.4 s
    t = np.array([math.pi / rate / 2, math.pi / rate])
    boat = Movers(np.zeros((1, 2)), np.array([[speed, 0.0]]), np.zeros(1), np.array([rate]), ONE)
    x, y = paths(boat, t)
    np.testing.assert_allclose(x[0], [12.5, 0.0], atol=1e-5)  # a quarter turn, then half
    np.testing.assert_allclose(y[0], [12.5, 25.0], atol=1e-5)
    a, b = arc(np.array([0.0, 1e-12]), np.array([2.0]))
    np.testing.assert_allclose(a, [[2.0], [2.0]])  # straight on: v t
    np.testing.assert_allclose(b, [[0.0], [0.0]], atol=1e-9)


def test_the_closest_approach_of_two_boats_on_straight_tracks_is_exact() -> None:
    t = sample_times(8.0)  # 1 s apart
    for ahead, when in ((40.0, 4.0), (45.0, 4.5), (52.5, 5.25)):  # on a sample and between
        rel = np.array([[ahead, 3.0]])  # head-on, 3 m apart sideways, closing at 10 m/s
        mine = Movers(np.zeros((1, 2)), np.array([[5.0, 0.0]]), np.zeros(1), np.zeros(1), ONE)
        other = Movers(rel, np.array([[-5.0, 0.0]]), np.array([math.pi]), np.zeros(1), ONE)
        theirs, law = paths(other, t), paths(mine, t)
        soon, gap2 = closest(rel, theirs, (law[0][:, None], law[1][:, None]), t)
        assert math.isclose(float(soon[0, 0]), when, rel_tol=1e-6)
        assert math.isclose(float(gap2[0, 0]), 9.0, rel_tol=1e-4)


def test_an_opening_pair_is_closest_now() -> None:
    t = sample_times(8.0)
    rel = np.array([[-20.0, 0.0]])  # astern, and we pull away
    mine = Movers(np.zeros((1, 2)), np.array([[5.0, 0.0]]), np.zeros(1), np.zeros(1), ONE)
    still = Movers(rel, np.zeros((1, 2)), np.zeros(1), np.zeros(1), ONE)
    law = paths(mine, t)
    soon, gap2 = closest(rel, paths(still, t), (law[0][:, None], law[1][:, None]), t)
    assert soon[0, 0] == 0.0 and math.isclose(float(gap2[0, 0]), 400.0, rel_tol=1e-6)
