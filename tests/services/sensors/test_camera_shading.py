"""Buoys wear a mark's colours (red, green, yellow, orange), vessels the instance palette."""

from __future__ import annotations

import numpy as np

from catabot.bus.messages import CLASS_BUOY, CLASS_VESSEL
from services.sensors.camera_shading import BUOY_PALETTE, PALETTE, SUN, lambert, shade


def test_each_buoy_instance_takes_a_marks_colour_and_vessels_the_palette() -> None:
    """A trial user's buoys came out teal and grey, lost against the water."""
    count = 8
    cls = np.array([CLASS_BUOY] * count + [CLASS_VESSEL] * count, dtype=np.uint8)
    inst = np.tile(np.arange(count, dtype=np.int32), 2)
    normal = np.tile(np.asarray(SUN, np.float32), (2 * count, 1))
    dirs = np.tile(np.array([1.0, 0.0, 0.0], np.float32), (2 * count, 1))
    rng = np.full(2 * count, 10.0, np.float32)
    out = shade(cls, inst, rng, normal, dirs, 1.0).T / lambert(normal[:1])[0]
    assert np.allclose(out[:count], BUOY_PALETTE[np.arange(count) % len(BUOY_PALETTE)])
    assert np.allclose(out[count:], PALETTE[np.arange(count)])
