"""Ray-casting sensors hit each vessel's shape, not its box: a LiDAR beam passes between a
catamaran's hulls and meets a hull on its surface, camera masks cover the hulls and not the
water between them, boxes and flags follow the shape, and the bodies' frames, normals and
cull are right for any pose."""

from __future__ import annotations

import math

import numpy as np
import open3d as o3d
import pytest

from catabot.bus.messages import CLASS_NONE, CLASS_VESSEL, CLASS_WATER, CameraFrame, VesselState
from catabot.config.sensors import CameraParams, LidarParams
from catabot.config.vessel import load_vessel_model
from catabot.config.waves import WaveConfig
from catabot.world.shapes import ShapeMesh, vessel_mesh
from catabot.world.waves import WaveField
from services.sensors.camera import CameraModel
from services.sensors.lidar import LidarModel
from services.sensors.mount import Mount
from services.sensors.scene import Body, Hits, Scene, SceneError

pytestmark = pytest.mark.filterwarnings("error::RuntimeWarning")  # an inf x 0 is a bug here
CALM = WaveField(WaveConfig(), 0)
LEVEL = LidarParams(channels=3, vertical_fov_deg=10.0, columns=360, mount_xyz=(0.0, 0.0, 0.1))


def _quat(yaw: float) -> tuple[float, float, float, float]:
    return (0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2))


def _state(x: float = 0.0, y: float = 0.0, yaw: float = 0.0) -> VesselState:
    zero = (0.0, 0.0, 0.0)
    return VesselState(0, 0, (x, y, 0.0), _quat(yaw), zero, zero, zero, zero)


def _mesh(model: str) -> ShapeMesh:
    mesh = vessel_mesh(load_vessel_model(model), source=model)
    assert mesh is not None
    return mesh


def _body(bid: str, model: str, instance: int, *, shape: bool = True) -> Body:
    """A bundled model as the sensors service makes it: its shape in its box, or its box."""
    if not shape:
        lo, hi = load_vessel_model(model).hull_box()
        return Body(bid, CLASS_VESSEL, instance, tuple(lo.tolist()), tuple(hi.tolist()))
    mesh = _mesh(model)
    return Body(bid, CLASS_VESSEL, instance, tuple(mesh.lo), tuple(mesh.hi), mesh)


def _scene(poses: dict[str, tuple[float, float, float]], *bodies: Body) -> Scene:
    scene = Scene(terrain=None, waves=CALM, bodies=list(bodies))
    scene.update({k: ((x, y, 0.0), _quat(yaw)) for k, (x, y, yaw) in poses.items()}, 0.0)
    return scene


def _level_ranges(scene: Scene, **state: float) -> np.ndarray:
    """The level channel of a 360-column LiDAR at 0.1 m: column j looks j degrees left."""
    lidar = LidarModel(LEVEL, Mount(scene=scene, noise=False))
    return lidar.sample(_state(**state), tick=0, stamp_ns=0).range_image[1]


def test_a_lidar_beam_passes_between_a_catamarans_hulls() -> None:
    """The catamaran 8 m ahead, bow away: the beam along its centreline goes under the deck
    (0.24 m up) between the pontoons; as a hull box it stopped at the stern (7.05 m)."""
    boxed = _level_ranges(_scene({"cat": (8.0, 0.0, 0.0)}, _body("cat", "catabot", 2, shape=False)))
    shaped = _level_ranges(_scene({"cat": (8.0, 0.0, 0.0)}, _body("cat", "catabot", 2)))
    assert boxed[0] == pytest.approx(7.05, abs=1e-3)
    assert np.isinf(shaped[[0, 1, 359]]).all()  # y within +-0.14 m at the stern: the gap
    for j in (3, 357):  # 3 degrees off the centreline: a pontoon's flat stern at x = 7.05 m
        assert shaped[j] == pytest.approx(7.05 / math.cos(math.radians(3.0)), abs=0.01)


def test_a_beam_onto_a_round_pontoon_hits_its_surface_within_a_centimetre() -> None:
    """A WAM-V beam-on to the south, turned and moved: the beam meets the starboard
    pontoon's cylinder (r 0.213 m, axis at z 0.124 m) where the analytic cylinder is."""
    scene = _scene({"w": (3.0, 8.0, math.pi)}, _body("w", "wamv", 2))  # bow west
    hits = scene.cast(np.array([2.5, 0.0, 0.15]), np.array([[0.0, 1.0, 0.0]]), 100.0)
    r, dz = 0.213, 0.15 - 0.124
    surface_y = 8.0 - 1.03 - math.sqrt(r * r - dz * dz)  # bow west: starboard is south
    assert hits.cls[0] == CLASS_VESSEL and hits.instance[0] == 2
    assert float(hits.range[0]) == pytest.approx(surface_y, abs=0.01)
    normal = np.array([0.0, -math.sqrt(r * r - dz * dz), dz]) / r
    assert np.allclose(hits.normal[0], normal, atol=0.15)  # 24 facets: within 7.5 degrees


def test_a_shaped_body_is_hit_where_an_independent_cast_of_its_placed_mesh_is() -> None:
    """Every ray of a scan against the mesh moved to the body's pose in a scene of its own:
    the same rays hit, at the same ranges (the body frame transforms are right)."""
    pose = (6.0, -4.0, 0.7)
    scene = _scene({"m": pose}, _body("m", "monohull", 2))
    origin, dirs = np.array([0.0, 0.0, 1.2]), _fan(4000, spread=0.3, towards=(6.0, -4.0, 0.5))
    hits = scene.cast(origin, dirs, 100.0)
    t = _independent(_mesh("monohull"), pose, origin, dirs)
    vessel = hits.cls == CLASS_VESSEL
    assert vessel.sum() > 500 and np.array_equal(
        vessel, np.isfinite(t) & (t < _water(origin, dirs))
    )
    assert np.allclose(hits.range[vessel], t[vessel], atol=1e-3)


def _fan(n: int, *, spread: float, towards: tuple[float, float, float]) -> np.ndarray:
    """n unit rays from (0, 0, 1.2) scattered about the direction to `towards` (seeded)."""
    aim = np.asarray(towards) - [0.0, 0.0, 1.2]
    scatter = np.random.default_rng(1).uniform(-spread, spread, (n, 3)) * [1.0, 1.0, 0.3]
    d = aim / np.linalg.norm(aim) + scatter
    return d / np.linalg.norm(d, axis=1, keepdims=True)


def _independent(
    mesh: ShapeMesh, pose: tuple[float, float, float], origin: np.ndarray, dirs: np.ndarray
) -> np.ndarray:
    """Ranges of rays against the mesh placed at (x, y, yaw) in a scene built for it."""
    x, y, yaw = pose
    c, s = math.cos(yaw), math.sin(yaw)
    world = mesh.vertices @ np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]).T + [x, y, 0]
    scene = o3d.t.geometry.RaycastingScene()
    scene.add_triangles(
        o3d.core.Tensor(world.astype(np.float32)), o3d.core.Tensor(mesh.triangles.astype(np.uint32))
    )
    rays = np.hstack([np.broadcast_to(origin, dirs.shape), dirs]).astype(np.float32)
    return scene.cast_rays(o3d.core.Tensor(rays))["t_hit"].numpy().astype(np.float64)


def _water(origin: np.ndarray, dirs: np.ndarray) -> np.ndarray:
    with np.errstate(divide="ignore"):
        t = -origin[2] / dirs[:, 2]
    return np.where(t > 0, t, np.inf)


def test_a_sensor_inside_a_shapes_box_but_outside_the_shape_sees_out() -> None:
    """A LiDAR between a WAM-V's pontoons, under its tray: the box holds it, the shape not;
    level beams leave the boat except where a pontoon or leg is in the way."""
    scene = _scene({"w": (0.0, 0.0, 0.0)}, _body("w", "wamv", 1))
    ranges = _level_ranges(scene)  # the sensor at (0, 0, 0.1)
    assert np.isinf(ranges[[0, 180]]).all()  # fore and aft, out between the pontoons
    r = math.sqrt(0.213**2 - (0.1 - 0.124) ** 2)
    assert ranges[90] == pytest.approx(1.03 - r, abs=0.01)  # the port pontoon's inner side
    assert ranges[270] == pytest.approx(1.03 - r, abs=0.01)


def test_normals_face_the_ray_whatever_the_winding() -> None:
    mesh = _mesh("catabot")
    flipped = ShapeMesh(mesh.vertices, mesh.triangles[:, ::-1].copy())
    for shape in (mesh, flipped):
        body = Body("c", CLASS_VESSEL, 2, tuple(shape.lo), tuple(shape.hi), shape)
        scene = _scene({"c": (6.0, 1.0, 0.4)}, body)
        dirs = _fan(2000, spread=0.4, towards=(6.0, 1.0, 0.2))
        hits = scene.cast(np.array([0.0, 0.0, 1.2]), dirs, 100.0)
        vessel = hits.cls == CLASS_VESSEL
        assert vessel.sum() > 100
        assert (np.einsum("ij,ij->i", hits.normal[vessel], dirs[vessel]) < 0).all()
        assert np.allclose(np.linalg.norm(hits.normal[vessel], axis=1), 1.0, atol=1e-5)


def test_a_shape_outside_its_box_is_refused() -> None:
    mesh = _mesh("buoy")
    with pytest.raises(SceneError, match="'b': its shape does not lie inside its box"):
        Scene(terrain=None, waves=CALM, bodies=[Body("b", 4, 1, (0, 0, 0), (1, 1, 1), mesh)])


def test_nothing_is_hit_beyond_range_or_before_a_nearer_body() -> None:
    far = _scene({"cat": (8.0, 0.0, 0.0)}, _body("cat", "catabot", 2))
    hits = far.cast(np.array([0.0, 0.0, 0.1]), np.array([[1.0, 0.04, 0.0]]), 5.0)
    assert hits.cls[0] == CLASS_NONE and np.isinf(hits.range[0])
    near = Body("near", CLASS_VESSEL, 3, (-0.1, -1.0, -0.1), (0.1, 1.0, 1.0))
    both = _scene(
        {"cat": (8.0, 0.0, 0.0), "near": (4.0, 0.0, 0.0)}, _body("cat", "catabot", 2), near
    )
    hits = both.cast(np.array([0.0, 0.0, 0.1]), np.array([[1.0, 0.04, 0.0]]), 50.0)
    assert hits.instance[0] == 3 and float(hits.range[0]) == pytest.approx(3.9 / 0.9992, abs=0.01)


def _camera_frame(scene: Scene, **params: object) -> tuple[CameraModel, CameraFrame]:
    cam = CameraModel(CameraParams.model_validate(params), Mount(scene=scene, seed=3, name="c"))
    return cam, cam.sample(_state(), tick=0, stamp_ns=0)


def test_the_masks_cover_the_hulls_and_not_the_water_between_them() -> None:
    """A WAM-V 10 m ahead, bow away, seen from 0.6 m up: the vessel mask is exactly the
    pixels whose rays meet its mesh before the water (an independent cast), so the water
    between the pontoons under the frame is water, not vessel (a box hid it)."""
    params = {"width": 480, "height": 360, "mount_xyz": (0.0, 0.0, 0.6)}
    cam, frame = _camera_frame(_scene({"w": (10.0, 0.0, 0.0)}, _body("w", "wamv", 2)), **params)
    _, boxed = _camera_frame(
        _scene({"w": (10.0, 0.0, 0.0)}, _body("w", "wamv", 2, shape=False)), **params
    )
    origin, rot = cam.pose(_state())
    dirs = cam.rays.astype(np.float64) @ rot.T
    t = _independent(_mesh("wamv"), (10.0, 0.0, 0.0), origin, dirs)
    expected = (np.isfinite(t) & (t < _water(origin, dirs))).reshape(360, 480)
    mask = frame.segmentation == CLASS_VESSEL
    assert expected.sum() > 800 and np.array_equal(mask, expected)
    assert np.all(frame.instance[mask] == 2)
    gap = _pixel(cam, (10.0 - 2.45, 0.0, 0.05))  # the middle of the gap at the stern
    assert frame.segmentation[gap] == CLASS_WATER
    assert boxed.segmentation[gap] == CLASS_VESSEL
    hull = _pixel(cam, (10.0 - 2.45, 1.03, 0.124))  # the port pontoon's stern
    assert frame.segmentation[hull] == CLASS_VESSEL


def _pixel(cam: CameraModel, point: tuple[float, float, float]) -> tuple[int, int]:
    origin, rot = cam.pose(_state())
    p = (np.asarray(point) - origin) @ rot
    u, v = cam.cam.fx * p[0] / p[2] + cam.cam.cx, cam.cam.fy * p[1] / p[2] + cam.cam.cy
    return int(v), int(u)


def test_boxes_and_flags_follow_the_shape() -> None:
    """Bow-on, a WAM-V fills under a third of its projected bounding box (two pontoons and
    a frame): it is not occluded, and its 2D box is its mask's. Behind a tall box that hides
    three quarters of it, it is; at the image edge, its projected outline leaves the image:
    truncated."""
    wamv = _body("w", "wamv", 2)
    params = {"width": 320, "height": 240, "mount_xyz": (0.0, 0.0, 1.5)}
    _, alone = _camera_frame(_scene({"w": (20.0, 0.0, 0.0)}, wamv), **params)
    row = np.flatnonzero(alone.boxes[:, 0] == 2)
    assert row.size == 1 and alone.box_flags[row[0]].tolist() == [0, 0, 100]  # all seen
    mask = np.argwhere(alone.instance == 2)
    x0, y0 = mask[:, 1].min(), mask[:, 0].min()
    x1, y1 = mask[:, 1].max() + 1, mask[:, 0].max() + 1
    assert alone.boxes[row[0], 2:].tolist() == [x0, y0, x1, y1]
    wall = Body("wall", CLASS_VESSEL, 3, (-0.2, -0.75, -0.1), (0.2, 0.75, 3.0))
    _, hidden = _camera_frame(
        _scene({"w": (20.0, 0.0, 0.0), "wall": (10.0, 0.3, 0.0)}, wamv, wall), **params
    )
    row = np.flatnonzero(hidden.boxes[:, 0] == 2)
    assert row.size == 1 and hidden.box_flags[row[0], 1] == 1
    seen = np.count_nonzero(hidden.instance == 2) / np.count_nonzero(alone.instance == 2)
    assert abs(hidden.box_flags[row[0], 2] - 100 * seen) <= 1  # visible: its share, in %
    edge_y = 18.0 * math.tan(math.radians(40.0))  # the left edge of the view at 18 m
    _, edge = _camera_frame(_scene({"w": (20.0, edge_y, 0.0)}, wamv), **params)
    row = np.flatnonzero(edge.boxes[:, 0] == 2)
    assert row.size == 1 and edge.box_flags[row[0], 0] == 1


def test_silhouettes_count_a_body_whatever_hides_it() -> None:
    wamv = _body("w", "wamv", 2)
    wall = Body("wall", CLASS_VESSEL, 3, (-0.2, -0.75, -0.1), (0.2, 0.75, 3.0))
    cam, _ = _camera_frame(_scene({"w": (20.0, 0.0, 0.0)}, wamv), width=320, height=240)
    origin, rot = cam.pose(_state())
    dirs = np.dot(cam.rays, rot.T.astype(np.float32))
    alone = _scene({"w": (20.0, 0.0, 0.0)}, wamv).cast(origin, dirs, 1e3, silhouettes=True)
    both = _scene({"w": (20.0, 0.0, 0.0), "wall": (10.0, 0.3, 0.0)}, wamv, wall)
    hidden = both.cast(origin, dirs, 1e3, silhouettes=True)
    assert alone.silhouette is not None and hidden.silhouette is not None
    assert alone.silhouette[0] == hidden.silhouette[0] == (alone.instance == 2).sum() > 50
    assert (hidden.instance == 2).sum() < alone.silhouette[0] / 2
    assert scene_without_silhouettes(wamv).silhouette is None


def scene_without_silhouettes(body: Body) -> Hits:
    scene = _scene({body.id: (20.0, 0.0, 0.0)}, body)
    return scene.cast(np.array([0.0, 0.0, 1.0]), np.array([[1.0, 0.0, 0.0]]), 100.0)


def test_level_rays_that_miss_count_no_silhouette_and_warn_nothing() -> None:
    """Horizontal rays (a level LiDAR channel, a camera's middle row) that miss a shape in
    its box: no silhouette pixel, no NaN from inf x 0."""
    scene = _scene({"w": (5.0, 0.0, 0.0)}, _body("w", "wamv", 2))
    dirs = np.array([[1.0, 0.0, 0.0], [1.0, 0.05, 0.0], [1.0, 0.5, 0.0], [1.0, 0.4, 0.0]])
    hits = scene.cast(np.array([0.0, 0.0, 0.3]), dirs, 100.0, silhouettes=True)
    assert np.isinf(hits.range[:3]).all() and hits.instance[3] == 2  # gap, gap, beside; hull
    assert hits.silhouette is not None and hits.silhouette.tolist() == [1]
