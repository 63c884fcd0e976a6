"""What a stack reads off an Observation (catabot/client/lockstep.py)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from catabot.bus.messages import BodyStates, VesselState
from catabot.client import Observation


def _seen(yaw: float | None) -> Observation:
    zero = (0.0, 0.0, 0.0)
    state = None if yaw is None else VesselState(
        tick=3, stamp_ns=40_000_000, position=zero,
        orientation=(0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2)),
        linear_velocity=zero, angular_velocity=zero,
        linear_acceleration=zero, angular_acceleration=zero,
    )  # fmt: skip
    empty = np.zeros((0, 3))
    bodies = BodyStates(3, 40_000_000, (), empty, np.zeros((0, 4)), empty, empty, empty, empty)
    return Observation(tick=4, stamp_ns=40_000_000, state=state, bodies=bodies, sensors={})


@pytest.mark.parametrize("yaw", [0.0, 1.2, -2.9, math.pi / 2])
def test_the_heading_is_read_off_the_quaternion(yaw: float) -> None:
    """Every stack (the README's, the examples') turned the quaternion into a yaw itself."""
    assert _seen(yaw).yaw_rad == pytest.approx(yaw, abs=1e-12)


def test_without_a_vessel_there_is_no_heading() -> None:
    assert math.isnan(_seen(None).yaw_rad)
