"""A target narrower than the gap between a beam's rays shows on every beam whose width holds
it (services/sensors/radar_fill.py). An audit moved a 0.44 m buoy round the antenna: at 200 m
it showed at 40 of 60 bearings, and then on one beam, where a 1.5 deg beam sees it on two."""

from __future__ import annotations

import math

import numpy as np
import pytest

from catabot.config.sensors import RadarParams
from services.sensors.mount import Mount
from services.sensors.radar import RadarModel
from tests.services.sensors.test_radar import DT, own, returns, scene_with, turn

BUOY = ((-0.22, -0.22, -0.3), (0.22, 0.22, 0.55))  # the bundled buoy's box, 0.44 m across


def _beams_seeing(bearing: float, range_m: float) -> np.ndarray:
    """The map bearings of the beams that saw a buoy at `bearing`, one turn."""
    scene = scene_with(range_m * math.cos(bearing), range_m * math.sin(bearing), 0.0, box=BUOY)
    radar = RadarModel(RadarParams(), Mount(scene=scene, period_ns=5 * DT, seed=1, name="r"))
    seen, _ = returns(turn(radar, own()), radar.step_rad)
    return seen


@pytest.mark.parametrize("range_m", [150.0, 240.0])
def test_a_buoy_far_off_shows_at_every_bearing_on_the_beams_whose_width_holds_it(
    range_m: float,
) -> None:
    """Without the fill: no beam at 12 of these 31 bearings, one at the others."""
    width, beams = math.radians(1.5), []
    for bearing in np.radians(np.linspace(0.05, 1.55, 31)):  # 0.05 deg apart: between rays
        seen = _beams_seeing(float(bearing), range_m)
        off = np.abs(np.angle(np.exp(1j * (seen - bearing))))
        assert seen.size >= 1 and off.max() <= width / 2 + 1e-9, (bearing, seen)
        beams.append(seen.size)
    assert beams.count(2) >= 0.9 * len(beams)  # beams half a width apart: two hold it


def test_a_buoy_the_rays_meet_is_not_counted_twice() -> None:
    """Near, the rays meet it: its returns are the rays' alone, as before the fill."""
    seen = _beams_seeing(0.3, 40.0)
    assert seen.size == np.unique(np.round(seen, 9)).size
