"""Plan-view hull boxes: their separation by the separating axis theorem."""

from __future__ import annotations

import math

import numpy as np
import pytest

from catabot.config.vessel import load_vessel_model
from catabot.world.hulls import box_gaps, footprints, hull_probes


def _gap(c: list[tuple[float, float]], yaw: list[float], half: list[tuple[float, float]]) -> float:
    a, b = np.array([0]), np.array([1])
    return float(box_gaps(np.array(c, float), np.array(yaw), np.array(half, float), a, b)[0])


SQUARES = [(1.0, 1.0), (1.0, 1.0)]


@pytest.mark.parametrize(
    ("centres", "yaw", "half", "gap"),
    [
        ([(0, 0), (5, 0)], [0, 0], SQUARES, 3.0),  # 5 - 1 - 1 along x
        ([(0, 0), (0, 3)], [0, 0], [(2.0, 0.5), (1.0, 1.0)], 1.5),  # 3 - 0.5 - 1 along y
        ([(0, 0), (3.5, 0)], [0, math.pi / 2], [(1.0, 1.0), (2.0, 0.5)], 2.0),  # b across: 0.5
        ([(0, 0), (1, 0)], [0, 0], SQUARES, -1.0),  # overlapping by 1 m
    ],
)
def test_box_gaps(
    centres: list[tuple[float, float]], yaw: list[float], half: list[tuple[float, float]],
    gap: float,
) -> None:  # fmt: skip
    assert _gap(centres, yaw, half) == pytest.approx(gap)


def test_corner_to_corner_is_a_lower_bound_of_the_distance() -> None:
    """Unit squares with a 45 degree one: its corner is sqrt(2)/2 from its centre."""
    gap = _gap([(0, 0), (3, 0)], [0, math.pi / 4], [(0.5, 0.5), (0.5, 0.5)])
    assert gap == pytest.approx(3 - 0.5 - math.sqrt(2) / 2)


def test_footprint_of_the_catamaran_is_its_collision_box() -> None:
    model = load_vessel_model("catabot")
    offset, half = footprints([model])
    np.testing.assert_allclose(offset, [[0.0, 0.0]])
    np.testing.assert_allclose(half, [[0.95, 0.52]])
    probes = hull_probes(model.hulls[0], 0.5)
    assert probes[:, 2].max() == pytest.approx(-0.06) and len(probes) == 5 * 2
