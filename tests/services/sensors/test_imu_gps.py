"""IMU and GPS models: physics of the readings, noise statistics, determinism, the registry."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pyproj
import pytest
from pydantic import ValidationError

from catabot.bus.messages import GpsFix, ImuSample, VesselState
from catabot.config.load import parse_scenario
from catabot.config.scenario import Origin
from catabot.config.sensors import SENSOR_TYPES, GpsParams, ImuParams
from catabot.config.waves import GRAVITY
from catabot.world.geo import enu_to_geodetic
from catabot.world.world import World
from services.sensors.common import SensorError
from services.sensors.gps import GpsModel
from services.sensors.imu import ImuModel
from services.sensors.mount import Mount
from services.sensors.registry import build_sensor, model_class

LEVEL = (0.0, 0.0, 0.0, 1.0)
DT_NS = 10_000_000
ORIGIN = (43.7, -72.3, 150.0)


def state(
    *,
    position=(0.0, 0.0, 0.0),
    orientation=LEVEL,
    angular_velocity=(0.0, 0.0, 0.0),
    linear_acceleration=(0.0, 0.0, 0.0),
    angular_acceleration=(0.0, 0.0, 0.0),
) -> VesselState:
    return VesselState(
        tick=0,
        stamp_ns=0,
        position=position,
        orientation=orientation,
        linear_velocity=(0.0, 0.0, 0.0),
        angular_velocity=angular_velocity,
        linear_acceleration=linear_acceleration,
        angular_acceleration=angular_acceleration,
    )


def about(axis: str, angle_rad: float) -> tuple[float, float, float, float]:
    s, c = math.sin(angle_rad / 2), math.cos(angle_rad / 2)
    return {"x": (s, 0.0, 0.0, c), "y": (0.0, s, 0.0, c), "z": (0.0, 0.0, s, c)}[axis]


MOUNT_FIELDS = ("noise", "seed", "name")


def make_imu(**kwargs: Any) -> ImuModel:
    """An IMU with these parameters and mount settings (seed, name, noise)."""
    mount = {k: kwargs.pop(k) for k in MOUNT_FIELDS if k in kwargs}
    return ImuModel(ImuParams(**kwargs), Mount(**{"name": "imu", **mount}))


def run_imu(model: ImuModel, n: int, st: VesselState | None = None) -> np.ndarray:
    """n samples as rows (gyro xyz, accel xyz), one tick apart."""
    st = st or state()
    out = []
    for k in range(n):
        s = model.sample(st, tick=k, stamp_ns=k * DT_NS)
        out.append(s.angular_velocity + s.linear_acceleration)
    return np.array(out)


@pytest.mark.parametrize(
    ("orientation", "expected"),
    [
        (LEVEL, (0.0, 0.0, GRAVITY)),
        (about("x", math.pi / 2), (0.0, GRAVITY, 0.0)),  # rolled right side down: +y is up
        (about("y", math.pi / 2), (-GRAVITY, 0.0, 0.0)),  # nose down: +x points down
        (about("z", 1.0), (0.0, 0.0, GRAVITY)),  # heading does not matter
    ],
)
def test_imu_reads_gravity_as_specific_force(orientation, expected) -> None:
    ideal = make_imu(noise=False).sample(state(orientation=orientation), tick=0, stamp_ns=0)
    assert isinstance(ideal, ImuSample)
    np.testing.assert_allclose(ideal.linear_acceleration, expected, atol=1e-12)
    assert ideal.orientation == orientation
    noisy = run_imu(make_imu(seed=3), 2000, state(orientation=orientation))
    np.testing.assert_allclose(noisy[:, 3:].mean(axis=0), expected, atol=0.02)  # bias + noise
    assert np.abs(noisy[:, 3:] - expected).max() < 5 * 0.021 + 0.02


def test_imu_lever_arm_and_motion() -> None:
    imu = make_imu(noise=False, lever_arm=(1.0, 0.0, 0.0))
    spinning = state(angular_velocity=(0.0, 0.0, 2.0), angular_acceleration=(0.0, 0.0, 0.5))
    s = imu.sample(spinning, tick=0, stamp_ns=0)
    # centripetal -w^2 r on x, tangential alpha x r on y, gravity on z
    np.testing.assert_allclose(s.linear_acceleration, (-4.0, 0.5, GRAVITY), atol=1e-12)
    np.testing.assert_allclose(s.angular_velocity, (0.0, 0.0, 2.0))
    surging = make_imu(noise=False).sample(
        state(linear_acceleration=(1.5, 0, 0)), tick=0, stamp_ns=0
    )
    np.testing.assert_allclose(surging.linear_acceleration, (1.5, 0.0, GRAVITY), atol=1e-12)


def test_imu_white_noise_matches_configured_sigma() -> None:
    imu = make_imu(gyro_bias_instability=0.0, accel_bias_instability=0.0, seed=11, name="v/imu")
    rows = run_imu(imu, 20000, state(angular_velocity=(0.1, -0.2, 0.3)))
    assert rows[:, :3].std(axis=0) == pytest.approx([0.009] * 3, rel=0.05)
    assert rows[:, 3:].std(axis=0) == pytest.approx([0.021] * 3, rel=0.05)
    np.testing.assert_allclose(rows[:, :3].mean(axis=0), (0.1, -0.2, 0.3), atol=3e-4)


def test_imu_gauss_markov_bias_has_its_sigma_and_correlation_time() -> None:
    tau, dt = 0.05, DT_NS * 1e-9
    imu = make_imu(gyro_sigma=0.0, accel_sigma=0.0, bias_tau_s=tau, seed=5)
    rows = run_imu(imu, 20000)
    bias = rows[:, :3]  # the gyro reads its bias only
    assert bias.std(axis=0) == pytest.approx([0.0008] * 3, rel=0.1)
    lag1 = np.mean([np.corrcoef(b[:-1], b[1:])[0, 1] for b in bias.T])
    assert lag1 == pytest.approx(math.exp(-dt / tau), abs=0.02)


def test_imu_bias_random_walk_grows_as_sqrt_time() -> None:
    finals = []
    for k in range(300):
        imu = make_imu(
            gyro_sigma=0.0,
            accel_sigma=0.0,
            gyro_bias_instability=0.0,
            accel_bias_instability=0.0,
            gyro_random_walk=1e-4,
            seed=k,
        )
        for step in range(26):
            last = imu.sample(state(), tick=step, stamp_ns=step * 1_000_000_000)
        finals.append(last.angular_velocity)
    assert np.std(finals) == pytest.approx(1e-4 * math.sqrt(25.0), rel=0.1)


def test_imu_is_deterministic_per_seed_and_name() -> None:
    a = run_imu(make_imu(seed=1, name="boat/imu"), 50)
    assert np.array_equal(a, run_imu(make_imu(seed=1, name="boat/imu"), 50))
    assert not np.allclose(a, run_imu(make_imu(seed=1, name="boat/imu2"), 50))
    assert not np.allclose(a, run_imu(make_imu(seed=2, name="boat/imu"), 50))


def test_imu_refuses_bad_input() -> None:
    with pytest.raises(ValidationError, match="gyro_sigma"):  # refused with the scenario
        make_imu(gyro_sigma=-1.0)
    with pytest.raises(ValidationError, match="bias_tau_s"):
        make_imu(bias_tau_s=0.0)
    imu = make_imu()
    imu.sample(state(), tick=1, stamp_ns=20)
    with pytest.raises(SensorError, match="stamp_ns went back from 20 to 10"):
        imu.sample(state(), tick=0, stamp_ns=10)
    with pytest.raises(SensorError, match="zero length"):
        make_imu().sample(state(orientation=(0, 0, 0, 0)), tick=0, stamp_ns=0)


def gps_at(origin=ORIGIN, **kwargs: Any) -> GpsModel:
    lat, lon, alt = origin
    mount = {k: kwargs.pop(k) for k in MOUNT_FIELDS if k in kwargs}
    place = Origin.model_construct(latitude_deg=lat, longitude_deg=lon, altitude_m=alt)
    return GpsModel(GpsParams(**kwargs), Mount(**{"name": "gps", **mount}, origin=place))


def fix_position(fix: GpsFix) -> tuple[float, float, float]:
    return fix.latitude, fix.longitude, fix.altitude


def test_gps_without_noise_at_origin_and_1000m_east() -> None:
    gps = gps_at(noise=False, altitude="ellipsoid")  # the exact conversion, altitude too
    fix = gps.sample(state(), tick=3, stamp_ns=30)
    assert isinstance(fix, GpsFix) and (fix.tick, fix.stamp_ns) == (3, 30)
    assert fix_position(fix) == pytest.approx(ORIGIN, abs=1e-9)
    assert (fix.horizontal_sigma, fix.vertical_sigma) == (0.0, 0.0)
    east = gps.sample(state(position=(1000.0, 0.0, 0.0)), tick=4, stamp_ns=40)
    pipeline = (
        f"+proj=pipeline +step +inv +proj=topocentric +ellps=WGS84 +lat_0={ORIGIN[0]}"
        f" +lon_0={ORIGIN[1]} +h_0={ORIGIN[2]} +step +inv +proj=cart +ellps=WGS84"
        " +step +proj=unitconvert +xy_in=rad +xy_out=deg"
    )
    lon, lat, alt = pyproj.Transformer.from_pipeline(pipeline).transform(1000.0, 0.0, 0.0)
    to_ecef = pyproj.Transformer.from_crs("EPSG:4979", "EPSG:4978", always_xy=True)
    ours = np.array(to_ecef.transform(east.longitude, east.latitude, east.altitude))
    assert np.linalg.norm(ours - np.array(to_ecef.transform(lon, lat, alt))) < 0.01


def test_gps_antenna_offset_follows_heading() -> None:
    gps = gps_at((0.0, 0.0, 0.0), noise=False, antenna_offset=(1.0, 0.0, 2.0), altitude="ellipsoid")
    fix = gps.sample(state(orientation=about("z", math.pi / 2)), tick=0, stamp_ns=0)
    expected = enu_to_geodetic(0.0, 1.0, 2.0, origin=(0.0, 0.0, 0.0))
    assert fix_position(fix) == pytest.approx(tuple(map(float, expected)), abs=1e-12)


def test_gps_noise_statistics_and_determinism() -> None:
    def offsets(model: GpsModel, n: int) -> np.ndarray:
        fixes = [fix_position(model.sample(state(), tick=k, stamp_ns=k)) for k in range(n)]
        return np.stack(model.frame.to_enu(*np.array(fixes).T), -1)

    model = gps_at(seed=4)
    enu = offsets(model, 5000)
    assert enu.std(axis=0) == pytest.approx([0.5, 0.5, 1.0], rel=0.05)
    assert np.array_equal(enu[:20], offsets(gps_at(seed=4), 20))
    assert not np.allclose(enu[:20], offsets(gps_at(seed=4, name="gps2"), 20))
    fix = model.sample(state(), tick=0, stamp_ns=0)
    assert (fix.horizontal_sigma, fix.vertical_sigma) == (0.5, 1.0)


@pytest.mark.parametrize(("where", "rise"), [((5000.0, 0.0), 1.96), ((0.0, -25000.0), 49.0)])
def test_gps_altitude_of_a_boat_on_the_water_is_the_origins_far_away(
    where: tuple[float, float], rise: float
) -> None:
    """The flat world as a local map: on the water the altitude is the origin's at 5 and
    25 km; the exact option shows the tangent plane's rise d^2 / 2R above the ellipsoid.
    Latitude and longitude are the same either way."""
    on_water = state(position=(*where, 0.0))
    local = gps_at(noise=False).sample(on_water, tick=0, stamp_ns=0)
    exact = gps_at(noise=False, altitude="ellipsoid").sample(on_water, tick=0, stamp_ns=0)
    assert local.altitude == pytest.approx(ORIGIN[2], abs=1e-9)
    assert exact.altitude - ORIGIN[2] == pytest.approx(rise, rel=0.01)  # R varies with heading
    assert (local.latitude, local.longitude) == (exact.latitude, exact.longitude)
    mast = gps_at(noise=False, antenna_offset=(0.0, 0.0, 3.0)).sample(on_water, tick=0, stamp_ns=0)
    assert mast.altitude == pytest.approx(ORIGIN[2] + 3.0, abs=1e-9)  # up is up on the map
    with pytest.raises(ValidationError, match="'ellipsoid' needs method 'wgs84'"):
        gps_at(method="paper_table", altitude="ellipsoid")


def test_gps_paper_table_method_and_errors() -> None:
    where = state(position=(700.0, -700.0, 0.0))
    exact = gps_at(noise=False).sample(where, tick=0, stamp_ns=0)
    paper = gps_at(noise=False, method="paper_table").sample(where, tick=0, stamp_ns=0)
    assert paper.latitude == pytest.approx(exact.latitude, abs=0.2 / 111_000)
    assert paper.longitude == pytest.approx(exact.longitude, abs=0.2 / 80_000)
    assert paper.altitude == pytest.approx(exact.altitude, abs=0.1)
    with pytest.raises(ValidationError, match="method"):  # refused with the scenario
        gps_at(method="utm")
    with pytest.raises(SensorError, match=r"origin: latitude \(deg\) must be within \[-90, 90\]"):
        gps_at((95.0, 0.0, 0.0))


def test_registry_builds_seeded_sensors() -> None:
    for name, spec in SENSOR_TYPES.items():  # every registered type has its model
        assert model_class(name).message is spec.message
    imu_cfg = {"name": "imu", "type": "imu", "rate_hz": 100.0}
    gps_cfg = {"name": "gps", "type": "gps", "rate_hz": 10.0, "noise": False}
    origin = dict(zip(("latitude_deg", "longitude_deg", "altitude_m"), ORIGIN, strict=True))
    vessels = [
        {"id": "boat1", "sensors": [imu_cfg, gps_cfg]},
        {"id": "boat2", "sensors": [imu_cfg]},
    ]
    scenario = {"seed": 9, "origin": origin, "vessels": vessels}
    world = World.resolve(parse_scenario(scenario))
    a, gps, c = (build_sensor(s, world) for s in world.sensors)
    b = build_sensor(world.sensors[0], world)
    assert a.message is ImuSample
    sa, sb, sc = (s.sample(state(), tick=0, stamp_ns=0) for s in (a, b, c))
    assert sa == sb and sa != sc  # seeded by the scenario seed and "<vessel>/<sensor>"
    fix = gps.sample(state(), tick=0, stamp_ns=0)
    assert gps.message is GpsFix and isinstance(fix, GpsFix)
    assert fix_position(fix) == pytest.approx(ORIGIN, abs=1e-9)
    with pytest.raises(SensorError, match="unknown sensor type 'sonar'"):
        model_class("sonar")
