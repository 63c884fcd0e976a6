"""An IMU slower than the physics tick describes its own interval, not the last tick
(services/sensors/imu.py): an audit's 10 Hz IMU in a 0.6 m sea read 0.14 / 0.12 / 0.32 m/s^2
rms off its interval's mean, and dead reckoning on it drifted 0.19 m/s in 18 s."""

from __future__ import annotations

import math

import numpy as np
import pytest

from catabot.bus.messages import VesselState
from catabot.config.load import parse_scenario
from catabot.config.sensors import ImuParams
from catabot.world import rotations
from catabot.world.world import World
from services.sensors.imu import ImuModel
from services.sensors.mount import Mount
from services.sensors.registry import build_sensor

TICK, PERIOD = 10_000_000, 100_000_000  # 100 Hz physics, a 10 Hz IMU
G = 9.81


def _imu(period_ns: int = PERIOD) -> ImuModel:
    return ImuModel(ImuParams(), Mount(name="imu", noise=False, period_ns=period_ns, tick_ns=TICK))


def _state(t: float, *, yaw: float, v: tuple[float, float, float], w: float) -> VesselState:
    """A state at t s: heading `yaw`, body velocity `v`, yaw rate `w`, and a last-tick
    acceleration the averaged IMU must not read (1000 m/s^2 up)."""
    q = rotations.from_yaw(yaw)
    stamp = round(t * 1e9)
    return VesselState(
        0, stamp, (0.0, 0.0, 0.0), q, v, (0.0, 0.0, w), (0.0, 0.0, 1000.0), (0.0,) * 3
    )


def test_heave_reads_the_intervals_mean_acceleration() -> None:
    """z = A sin(W t): over [t0, t1] the mean of z'' is A W (cos W t1 - cos W t0) / T."""
    a, big_w, t0, t1 = 0.3, 2.0, 1.0, 1.1
    imu = _imu()
    for t in (t0, t1):
        heave = a * big_w * math.cos(big_w * t)
        sample = imu.sample(_state(t, yaw=0.0, v=(0.0, 0.0, heave), w=0.0), tick=0,
                            stamp_ns=round(t * 1e9))  # fmt: skip
    mean = a * big_w * (math.cos(big_w * t1) - math.cos(big_w * t0)) / (t1 - t0)
    assert sample.linear_acceleration[2] == pytest.approx(mean + G, abs=1e-9)


def test_the_rate_is_the_turn_over_the_interval_and_a_turn_bends_the_velocity() -> None:
    """Turning at r with surge u: the mean yaw rate is r whatever the state's last-tick rate,
    and the mean acceleration is the chord of the velocity's turn, centripetal in the
    interval's middle axes: u (2 sin(r T / 2)) / T across."""
    r, u, t0, t1 = 0.4, 2.0, 5.0, 5.1
    imu = _imu()
    for t, last_rate in ((t0, 9.0), (t1, -9.0)):
        sample = imu.sample(_state(t, yaw=r * t, v=(u, 0.0, 0.0), w=last_rate), tick=0,
                            stamp_ns=round(t * 1e9))  # fmt: skip
    assert sample.angular_velocity[2] == pytest.approx(r, abs=1e-9)
    chord = u * 2.0 * math.sin(r * (t1 - t0) / 2.0) / (t1 - t0)
    assert np.allclose(sample.linear_acceleration, (0.0, chord, G), atol=1e-9)


def test_an_imu_at_the_tick_rate_reads_the_state_as_before() -> None:
    imu, state = _imu(period_ns=TICK), _state(1.0, yaw=0.0, v=(1.0, 0.0, 0.0), w=0.5)
    imu.sample(state, tick=0, stamp_ns=state.stamp_ns)
    sample = imu.sample(state, tick=1, stamp_ns=state.stamp_ns + TICK)
    assert sample.linear_acceleration[2] == pytest.approx(1000.0 + G)
    assert sample.angular_velocity[2] == 0.5


def test_a_run_gives_its_imus_the_physics_tick() -> None:
    world = World.resolve(parse_scenario({"vessels": [
        {"id": "ego", "sensors": [{"name": "imu", "type": "imu", "rate_hz": 10.0}]}]}))  # fmt: skip
    imu = build_sensor(world.sensors[0], world)
    assert isinstance(imu, ImuModel) and imu._averages
