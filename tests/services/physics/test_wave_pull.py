"""The waves' horizontal pull (services/physics/wave_pull.py): the fitted surface slope, a
hull at rest in a long regular wave swinging as far as the water it floats in, and a small
buoy tilting with the surface whatever the height of its centre of gravity."""

from __future__ import annotations

import numpy as np
import pytest

from catabot.config.vessel import load_vessel_model
from catabot.config.waves import WaveConfig
from catabot.world import rotations
from catabot.world.waves import WaveField
from services.physics.hydro import build_columns
from services.physics.wave_pull import surface_slopes
from services.physics.world import PhysicsWorld


def test_the_slope_of_a_plane_is_found_whatever_the_heading() -> None:
    cols = build_columns([load_vessel_model("wamv")])
    rot = rotations.matrices(np.array([rotations.from_yaw(0.7)]))
    world = np.matmul(rot, cols.bottom_m)  # (1, 3, C)
    eta = 0.1 + 0.02 * world[:, 0] - 0.03 * world[:, 1]
    assert surface_slopes(rot, cols.bottom_m, cols.area_m2, eta)[0] == pytest.approx(
        [0.02, -0.03, 0.0], abs=1e-12
    )


def test_a_hull_on_its_side_has_no_slope() -> None:
    """Seen from above its columns lie on a line: no plane to fit, so no pull (not a NaN)."""
    cols = build_columns([load_vessel_model("catabot")])
    rot = rotations.matrices(np.array([rotations.from_rpy(np.pi / 2, 0.0, 0.0)]))
    eta = np.random.default_rng(1).normal(size=cols.area_m2.shape)
    assert (surface_slopes(rot, cols.bottom_m, cols.area_m2, eta) == 0.0).all()


def _regular_wave() -> WaveField:
    cfg = WaveConfig(significant_height_m=0.5, peak_period_s=6.0, gamma=10, spreading=None,
                     frequency_components=1, direction_components=1, direction_rad=0.0)  # fmt: skip
    return WaveField(cfg, 1)


@pytest.mark.parametrize("cog_z", [-0.08, -0.04, 0.0])
def test_a_small_buoy_tilts_with_the_surface_of_a_long_wave(cog_z: float) -> None:
    """Moving with the water, a body short against the wave feels gravity less the water's
    acceleration, normal to the surface: it pitches with the slope (times 1.08 for the
    bundled buoy's 1.64 s pitch period against 6 s). With the added mass's pull at the
    centre of buoyancy and its reaction at the origin, the buoy pitched 0.36 of the slope,
    and 0.01 of it with its centre of gravity at -0.04 m."""
    waves = _regular_wave()
    buoy = load_vessel_model("buoy").model_copy(update={"cog_m": (0.0, 0.0, cog_z)})
    world = PhysicsWorld([("b", buoy, (0.0, 0.0, 0.0, 0.0))], dt_s=0.01, waves=waves)
    pitch = []
    for k in range(2300):  # 10 s to settle, then two wave periods
        world.step()
        if k >= 1000:
            bow = rotations.matrices(world.state_arrays().orientation)[0, :, 0]
            pitch.append(np.arcsin(bow[2]))  # the bow's rise: the tilt about y
    slope = waves.wavenumbers_radpm[0] * waves.amplitudes_m[0]
    assert np.ptp(pitch) / 2 / slope == pytest.approx(1.04, abs=0.1)


@pytest.mark.parametrize("name", ["catabot", "wamv"])
def test_a_hull_at_rest_swings_with_the_water_of_a_long_wave(name: str) -> None:
    """A naval architect's check: a hull short against the wave moves with the water's
    particles, horizontally as vertically; with buoyancy pushing straight up, the damping
    alone dragged it a third of the way (0.18-0.5 of the particles' swing)."""
    waves = _regular_wave()
    world = PhysicsWorld([("v", load_vessel_model(name), (0.0, 0.0, 0.0, 0.0))], dt_s=0.01,
                         waves=waves)  # fmt: skip
    x = np.empty(4000)
    for k in range(6000):
        world.step()
        if k >= 2000:
            x[k - 2000] = world.state_arrays().position[0, 0]
    t = np.arange(4000) * 0.01
    swing = x - np.polyval(np.polyfit(t, x, 1), t)  # less the slow drift
    particle = waves.amplitudes_m[0] / np.sqrt(2.0)  # a surface particle's circle, std
    assert swing.std() / particle == pytest.approx(1.0, abs=0.1)
