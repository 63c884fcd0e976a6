"""Marine radar: bearing and range of a boat, range noise, rain independence, PPI fading."""

from __future__ import annotations

import math

import numpy as np
import pytest
from pydantic import ValidationError

from catabot.bus.messages import CLASS_VESSEL, RadarSweep, VesselState
from catabot.config.sensors import RadarParams
from catabot.config.waves import WaveConfig
from catabot.ros2.ppi import Ppi
from catabot.world.waves import WaveField
from services.sensors.mount import Mount
from services.sensors.radar import RadarModel
from services.sensors.scene import Body, Scene

BOAT = ((-2.0, -1.0, -0.2), (2.0, 1.0, 1.0))
WALL = ((-2.0, -60.0, -1.0), (2.0, 60.0, 5.0))
DT = 10_000_000


def yaw_q(yaw: float) -> tuple[float, float, float, float]:
    return (0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2))


def own(yaw: float = 0.0) -> VesselState:
    zero = (0.0, 0.0, 0.0)
    return VesselState(0, 0, zero, yaw_q(yaw), zero, zero, zero, zero)


def scene_with(x: float, y: float, yaw: float, box=BOAT, rain: float = 0.0) -> Scene:
    bodies = [
        Body("own", CLASS_VESSEL, 1, (-1.0, -0.5, -0.1), (1.0, 0.5, 0.3)),
        Body("b", CLASS_VESSEL, 2, *box),
    ]
    scene = Scene(terrain=None, waves=WaveField(WaveConfig(), 0), bodies=bodies)
    scene.rain_rate_mm_h = rain
    scene.update({"own": ((0.0, 0.0, 0.0), yaw_q(0.0)), "b": ((x, y, 0.0), yaw_q(yaw))}, 0.0)
    return scene


def turn(radar: RadarModel, state: VesselState, turns: float = 1.0) -> list[RadarSweep]:
    n = round(turns * radar.turn_ns / radar.period_ns)
    return [radar.sample(state, tick=k, stamp_ns=k * radar.period_ns) for k in range(n)]


def returns(sweeps: list[RadarSweep], step: float) -> tuple[np.ndarray, np.ndarray]:
    """(map bearing, first range) of every beam that saw something."""
    bearing, rng = [], []
    for s in sweeps:
        az = s.heading_rad + s.azimuth_start_rad - step * np.arange(s.beams)
        hit = np.isfinite(s.ranges)
        bearing += list(az[hit])
        rng += list(s.ranges[hit])
    return np.array(bearing), np.array(rng)


@pytest.mark.parametrize("bearing_deg, heading_deg", [(0.0, 0.0), (120.0, 30.0), (-75.0, 200.0)])
def test_sees_a_boat_at_200_m_at_its_bearing_and_range(
    bearing_deg: float, heading_deg: float
) -> None:
    b = math.radians(bearing_deg)
    scene = scene_with(200 * math.cos(b), 200 * math.sin(b), b)  # bow toward us: face at 198 m
    radar = RadarModel(RadarParams(), Mount(scene=scene, period_ns=5 * DT, seed=1, name="v/radar"))
    bearing, rng = returns(turn(radar, own(math.radians(heading_deg))), radar.step_rad)
    assert bearing.size > 0
    width = math.radians(RadarParams().beam_width_deg)
    off = np.angle(np.exp(1j * (bearing - b)))
    assert np.abs(off).max() <= width
    assert abs(float(np.median(rng)) - 198.0) < 3 * 0.2


@pytest.mark.parametrize(
    "params",
    [RadarParams(sub_rays=1, elevations_deg=(0.0,), fan_target_height_m=0.0), RadarParams()],
    ids=["one ray a beam", "the default beam of many rays"],
)
def test_range_noise_sigma(params: RadarParams) -> None:
    """The reading is N(true, sigma): with many rays a beam, the nearest of their noisy
    ranges had been reported, 0.2 m short with a spread of 0.15 m."""
    errors = []
    for noise in (True, False):
        radar = RadarModel(
            params,
            Mount(
                scene=scene_with(100.0, 0.0, 0.0, WALL),
                period_ns=10 * DT,
                noise=noise,
                seed=2,
                name="v/r",
            ),
        )
        errors.append(returns(turn(radar, own(), turns=6), radar.step_rad)[1])
    diff = errors[0].astype(np.float64) - errors[1]
    assert diff.size > 300
    assert abs(diff.std() / 0.2 - 1.0) < 0.1 and abs(diff.mean()) < 0.05


def test_rain_does_not_change_the_returns() -> None:
    sweeps = []
    for rain in (0.0, 50.0):
        radar = RadarModel(
            RadarParams(),
            Mount(
                scene=scene_with(150.0, 20.0, 0.3, rain=rain), period_ns=5 * DT, seed=4, name="v/r"
            ),
        )
        sweeps.append(turn(radar, own(), 0.5))
    for a, b in zip(*sweeps, strict=True):
        assert (
            a.intensity.tobytes() == b.intensity.tobytes()
            and a.ranges.tobytes() == b.ranges.tobytes()
        )
    with pytest.raises(ValidationError):
        RadarParams.model_validate({"rain_rate_mm_h": 10.0})


def test_water_is_not_a_return_and_sweeps_tile_the_turn() -> None:
    radar = RadarModel(
        RadarParams(), Mount(scene=scene_with(5000.0, 0.0, 0.0), period_ns=DT, seed=1, name="v/r")
    )
    sweeps = turn(radar, own())
    assert sum(s.beams for s in sweeps) == radar.beams_per_turn
    assert all(not s.intensity.any() and np.isinf(s.ranges).all() for s in sweeps)


def test_ppi_paints_north_up_and_fades() -> None:
    scene = scene_with(0.0, 150.0, math.pi / 2)  # due north
    radar = RadarModel(RadarParams(), Mount(scene=scene, period_ns=5 * DT, seed=1, name="v/r"))
    p = RadarParams()
    ppi = Ppi(size_px=p.ppi_size_px, range_m=p.range_m, fade_s=p.fade, beam_step_rad=radar.step_rad)
    sweeps = turn(radar, own(math.radians(45.0)))
    for s in sweeps:
        ppi.add(s)
    painted = max((s for s in sweeps if np.isfinite(s.ranges).any()), key=lambda s: s.stamp_ns)
    now = painted.stamp_ns
    img = ppi.render(now)
    rows, cols = np.nonzero(img)
    assert rows.size > 0
    centre = p.ppi_size_px / 2
    assert np.all(rows < centre - 50) and np.all(np.abs(cols - centre) < 8)  # above: north
    peak = int(img.max())
    assert p.fade == 3.0  # a turn and a half: the image made once a turn shows all of it
    half = ppi.render(now + int(1.5e9))
    assert 0.4 * peak <= int(half.max()) <= 0.6 * peak + 1
    turn_later = int(ppi.render(now + int(2.0e9)).max())  # (1 s showed half a turn)
    assert 0.25 * peak <= turn_later <= 0.4 * peak + 1
    assert not ppi.render(now + int(3.01e9)).any()
