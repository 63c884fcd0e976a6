"""The shared ray-casting scene and the LiDAR on it: ranges, surfaces, labels, determinism."""

from __future__ import annotations

import math
import re

import numpy as np
import pytest

from catabot.bus.messages import (
    CLASS_BUOY,
    CLASS_NONE,
    CLASS_TERRAIN,
    CLASS_VESSEL,
    CLASS_WATER,
    LidarScan,
    VesselState,
)
from catabot.config.base import ScenarioError
from catabot.config.load import parse_scenario
from catabot.config.sensors import LidarParams
from catabot.config.waves import WaveConfig
from catabot.world.terrain import Terrain
from catabot.world.waves import WaveField
from services.sensors.lidar import LidarModel, beam_directions
from services.sensors.mount import Mount
from services.sensors.scene import Body, Scene, SceneError

CALM = WaveField(WaveConfig(), 0)
EGO = Body("ego", CLASS_VESSEL, 1, (-1.0, -0.5, -0.1), (1.0, 0.5, 0.2))
BOAT = Body("boat", CLASS_VESSEL, 2, (-2.0, -1.0, -0.2), (2.0, 1.0, 1.0))
BUOY = Body("buoy", CLASS_BUOY, 3, (-0.2, -0.2, -0.15), (0.2, 0.2, 0.85))
LEVEL = LidarParams(channels=3, vertical_fov_deg=10.0, columns=360, mount_xyz=(0.0, 0.0, 0.5))


def _quat(yaw: float) -> tuple[float, float, float, float]:
    return (0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2))


def _state(x: float = 0.0, y: float = 0.0, yaw: float = 0.0) -> VesselState:
    zero = (0.0, 0.0, 0.0)
    return VesselState(0, 0, (x, y, 0.0), _quat(yaw), zero, zero, zero, zero)


def _scene(waves: WaveField = CALM, rain: float = 0.0, **poses: tuple[float, ...]) -> Scene:
    scene = Scene(terrain=None, waves=waves, bodies=[EGO, BOAT, BUOY], rain_rate_mm_h=rain)
    scene.update({k: ((v[0], v[1], 0.0), _quat(v[2])) for k, v in poses.items()}, 0.0)
    return scene


def test_lidar_hits_a_posed_box_at_the_known_range() -> None:
    scene = _scene(ego=(0, 0, 0), boat=(20.0, 0.0, 0.0), buoy=(0.0, -10.0, 0.0))
    scan = LidarModel(LEVEL, Mount(scene=scene, noise=False)).sample(_state(), tick=3, stamp_ns=7)
    assert isinstance(scan, LidarScan) and (scan.tick, scan.stamp_ns) == (3, 7)
    level = scan.range_image[1]  # channel 1 is level; column j looks at j degrees
    assert level[0] == pytest.approx(18.0, abs=0.01)  # the boat's stern face at x = 18
    assert level[270] == pytest.approx(9.8, abs=0.01)  # the buoy's north face at y = -9.8
    front = np.flatnonzero((scan.ring == 1) & (np.abs(scan.points[:, 1]) < 0.5))
    front = front[scan.points[front, 0] > 0]
    assert set(scan.cls[front]) == {CLASS_VESSEL} and set(scan.instance[front]) == {2}
    buoy = (scan.ring == 1) & (scan.points[:, 1] < -9.0) & (np.abs(scan.points[:, 0]) < 0.2)
    assert set(scan.cls[buoy]) == {CLASS_BUOY} and set(scan.instance[buoy]) == {3}
    down = scan.ring == 0  # 5 degrees down from 0.5 m: the calm sea at 5.7 m
    water = down & (scan.cls == CLASS_WATER)
    assert water.sum() > 300 and np.all(scan.instance[water] == 0)
    assert np.allclose(scan.points[water, 2], -0.5, atol=1e-4)  # z = 0 in the sensor frame


def test_a_turned_box_and_a_moving_sensor() -> None:
    scene = _scene(ego=(5, 5, 0), boat=(25.0, 5.0, math.pi / 2))  # beam-on: 1 m half-width
    scan = LidarModel(LEVEL, Mount(scene=scene, noise=False)).sample(
        _state(5, 5), tick=0, stamp_ns=0
    )
    assert scan.range_image[1, 0] == pytest.approx(19.0, abs=0.01)
    turned = LidarModel(LEVEL, Mount(scene=scene, noise=False)).sample(
        _state(5, 5, math.pi / 2), tick=0, stamp_ns=0
    )
    assert turned.range_image[1, 270] == pytest.approx(19.0, abs=0.01)  # boat now to the right


def test_water_hits_lie_on_the_wave_surface() -> None:
    waves = WaveField(WaveConfig(preset="heavy"), 4)
    scene = _scene(waves)
    scene.update({}, 12.5)
    d = beam_directions(32, 512, 45.0)
    origin = np.array([10.0, -3.0, 2.5])
    hits = scene.cast(origin, d, 100.0)
    water = hits.cls == CLASS_WATER
    assert water.sum() > 5000
    p = origin + hits.range[water, None].astype(np.float64) * d[water]
    assert np.abs(p[:, 2] - waves.height(p[:, 0], p[:, 1], 12.5)).max() < 0.01
    assert np.allclose(hits.normal[water], waves.normal(p[:, 0], p[:, 1], 12.5), atol=1e-3)


def test_terrain_hits_match_the_height_field() -> None:
    x = np.arange(200) + 0.5
    terrain = Terrain(np.add.outer(np.zeros(200), 2.0 + 0.05 * x + np.sin(x / 9)), 1.0)
    scene = Scene(terrain=terrain, waves=CALM, bodies=[])
    d = beam_directions(16, 64, 60.0) @ np.array([[1, 0, 0], [0, 1, 0], [0, 0, 1.0]]).T
    d[:, 2] -= 1.5  # every ray well downward
    origin = np.array([100.0, 100.0, 30.0])
    hits = scene.cast(origin, d, 200.0)
    assert np.all(hits.cls == CLASS_TERRAIN) and np.all(hits.instance == 0)
    dn = d / np.linalg.norm(d, axis=1, keepdims=True)
    p = origin + hits.range[:, None].astype(np.float64) * dn
    assert np.abs(p[:, 2] - terrain.height(p[:, 0], p[:, 1])).max() < 0.05
    assert np.all(hits.normal[:, 2] > 0.9)


def test_nothing_in_range_is_none_and_culling_keeps_far_bodies_out() -> None:
    far = [Body(f"b{i}", CLASS_VESSEL, 10 + i, (-1, -1, 0), (1, 1, 1)) for i in range(100)]
    scene = Scene(terrain=None, waves=CALM, bodies=far)
    scene.update({f"b{i}": ((500.0 + 10 * i, 0.0, 0.0), _quat(0.0)) for i in range(100)}, 0.0)
    hits = scene.cast(np.array([0.0, 0.0, 1.0]), np.array([[1.0, 0.0, 0.0], [0, 0, 1.0]]), 100.0)
    assert np.all(np.isinf(hits.range)) and np.all(hits.cls == CLASS_NONE)
    assert np.all(hits.normal == 0)
    with pytest.raises(SceneError, match="unknown body 'nope'"):
        scene.update({"nope": ((0, 0, 0), (0, 0, 0, 1))}, 0.0)


def test_scans_are_deterministic_and_rain_is_labelled() -> None:
    scene = _scene(rain=50.0, ego=(0, 0, 0), boat=(30.0, 0.0, 0.0))
    params = LidarParams(mount_xyz=(0.0, 0.0, 1.0))
    a, b, c = (LidarModel(params, Mount(scene=scene, seed=s, name="ego/lidar")) for s in (1, 1, 2))
    sa, sb, sc = (m.sample(_state(), tick=0, stamp_ns=0) for m in (a, b, c))
    for name in ("points", "intensity", "ring", "cls", "instance", "is_rain", "range_image"):
        assert np.array_equal(getattr(sa, name), getattr(sb, name))
    assert not np.array_equal(sa.range_image, sc.range_image)
    assert sa.range_image.shape == (32, 512) and sa.points.dtype == np.float32
    assert sa.is_rain.any() and np.all(sa.cls[sa.is_rain] == CLASS_NONE)
    assert np.all(sa.instance[sa.is_rain] == 0)


def test_no_return_nearer_than_the_minimum_range() -> None:
    """The paper's rain model puts many drops within centimetres of the sensor (the nearest
    drop backscatters most); a real LiDAR's blind zone reports none there."""
    scene = _scene(rain=50.0, ego=(0, 0, 0), boat=(30.0, 0.0, 0.0))
    ranges = {}
    for near in (0.0, 1.0):
        params = LidarParams(mount_xyz=(0.0, 0.0, 1.0), min_range_m=near)
        scan = LidarModel(params, Mount(scene=scene, seed=1, name="ego/lidar")).sample(
            _state(), tick=0, stamp_ns=0
        )
        ranges[near] = (np.linalg.norm(scan.points, axis=1), scan)
    seen, blind = ranges[0.0], ranges[1.0]
    assert (seen[0] < 1.0).sum() > 100 and seen[1].is_rain[seen[0] < 1.0].all()
    assert blind[0].min() >= 1.0 and blind[1].is_rain.any()  # drops beyond it still show
    assert not (blind[1].range_image < 1.0).any()
    with pytest.raises(ValueError, match="min_range_m"):
        LidarParams(min_range_m=100.0)


def test_pose_arrays_from_a_batch_equal_the_named_poses() -> None:
    """The sensors service's per-tick path (batch arrays) casts exactly like named poses;
    a bad row is still named."""
    ids = ("boat", "buoy", "ego")  # not the scene's order
    pos = np.array([[20.0, 1.0, 0.0], [0.0, -10.0, 0.1], [0.0, 0.0, 0.0]])
    quat = np.array([_quat(0.3), _quat(0.0), _quat(-0.2)])
    named, arrays = _scene(), _scene()
    named.update({b: (pos[i], quat[i]) for i, b in enumerate(ids)}, 2.0)
    arrays.update_arrays(ids, pos, quat, 2.0)
    scans = [
        LidarModel(LEVEL, Mount(scene=s, noise=False)).sample(_state(), tick=0, stamp_ns=0)
        for s in (named, arrays)
    ]
    assert np.array_equal(scans[0].range_image, scans[1].range_image)
    assert arrays.time_s == 2.0
    pos[1, 0] = np.nan
    with pytest.raises(SceneError, match="buoy"):
        arrays.update_arrays(ids, pos, quat, 3.0)


def test_lambertian_water_returns_end_where_its_echo_falls_below_the_threshold() -> None:
    """A beam dipping onto calm water from height h meets it at Z with cos(incidence) = h / Z,
    so its echo s / pi (h / Z) / Z^2 passes the threshold t while Z^3 < s h / (pi t): 10.8 m
    for the default water (s 0.02) seen from 1 m. The same beams, paper model: water to 79 m."""
    scene = _scene(ego=(0, 0, 0), boat=(30.0, 0.0, 0.0), buoy=(0.0, -10.0, 0.0))
    scans = {}
    for model in ("paper", "lambertian"):
        params = LidarParams(mount_xyz=(0.0, 0.0, 1.0), reflection=model)
        mount = Mount(scene=scene, noise=False, seed=1, name="ego/lidar")
        scans[model] = LidarModel(params, mount).sample(_state(), tick=0, stamp_ns=0)
    reach = (0.02 * 1.0 / (math.pi * 5e-6)) ** (1 / 3)
    paper, lambertian = scans["paper"], scans["lambertian"]
    water = {m: np.linalg.norm(s.points[s.cls == CLASS_WATER], axis=1) for m, s in scans.items()}
    assert water["paper"].max() > 70.0 and water["lambertian"].max() < reach
    assert np.array_equal(
        np.sort(water["lambertian"]), np.sort(water["paper"][water["paper"] < reach])
    )
    boat = lambertian.cls == CLASS_VESSEL  # face-on at 28 m (the boat's stern): s 0.6, cos 1
    ahead = boat & (lambertian.ring == 15) & (np.abs(lambertian.points[:, 1]) < 0.05)
    z = np.linalg.norm(lambertian.points[ahead], axis=1)
    cos = lambertian.points[ahead, 0] / z
    assert np.allclose(lambertian.intensity[ahead], 0.6 / math.pi * cos / z**2, rtol=1e-4)
    assert (paper.cls == CLASS_VESSEL).sum() == boat.sum()  # a hull's echo is far above it


@pytest.mark.parametrize(
    ("params", "said"),
    [
        ({"surface_reflectivity": {"water": 0.1}},
         "params.surface_reflectivity: applies with reflection 'lambertian'"),
        ({"reflection": "lambertian", "reflectivity": 0.5},
         "params.reflectivity: is the paper model's one value for every surface"),
        ({"reflection": "lambertian", "surface_reflectivity": {"water": 0.0}},
         "params.surface_reflectivity.water: must be > 0 (got 0.0)"),
    ],
)  # fmt: skip
def test_a_reflectivity_the_chosen_model_ignores_is_refused(
    params: dict[str, object], said: str
) -> None:
    lidar = {"name": "lidar", "type": "lidar", "rate_hz": 10.0, "params": params}
    data = {"name": "refl", "vessels": [{"id": "ego", "sensors": [lidar]}]}
    with pytest.raises(ScenarioError, match=re.escape(f"vessels.0.sensors.0.{said}")):
        parse_scenario(data)
