"""Camera: labels agree with the geometry (segmentation, boxes, flags), depth and normals are
exact on known surfaces, rain lowers contrast, frames are deterministic."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from catabot.bus.messages import CLASS_NONE, CLASS_VESSEL, CLASS_WATER, CameraFrame, VesselState
from catabot.config.sensors import CameraParams
from catabot.config.waves import WaveConfig
from catabot.world.waves import WaveField
from services.sensors.camera import CameraModel
from services.sensors.camera_shading import VEIL
from services.sensors.mount import Mount
from services.sensors.scene import Body, Scene

BOAT = ((-2.0, -1.0, -0.2), (2.0, 1.0, 1.0))
TALL = ((-2.0, -1.0, -0.2), (2.0, 1.0, 3.0))
LEVEL = (0.0, 0.0, 0.0, 1.0)


def own_state() -> VesselState:
    zero = (0.0, 0.0, 0.0)
    return VesselState(0, 0, zero, LEVEL, zero, zero, zero, zero)


def scene_with(boats: dict[str, tuple[float, float, tuple[tuple[float, ...], ...]]]) -> Scene:
    """Own vessel at the origin plus boats {id: (x, y, (lo, hi))}, calm water, no terrain."""
    bodies = [Body("own", CLASS_VESSEL, 1, (-1.0, -0.5, -0.1), (1.0, 0.5, 0.3))]
    for i, (bid, (_, _, (lo, hi))) in enumerate(boats.items()):
        bodies.append(Body(bid, CLASS_VESSEL, 2 + i, lo, hi))  # type: ignore[arg-type]
    scene = Scene(terrain=None, waves=WaveField(WaveConfig(), 0), bodies=bodies)
    poses = {"own": ((0.0, 0.0, 0.0), LEVEL)}
    poses |= {bid: ((x, y, 0.0), LEVEL) for bid, (x, y, _) in boats.items()}
    scene.update(poses, 0.0)
    return scene


def shoot(scene: Scene, **params: object) -> tuple[CameraModel, CameraFrame]:
    cam = CameraModel(CameraParams.model_validate(params), Mount(scene=scene, seed=3, name="v/cam"))
    return cam, cam.sample(own_state(), tick=0, stamp_ns=0)


def project(cam: CameraModel, points: np.ndarray) -> np.ndarray:
    origin, rot = cam.pose(own_state())
    p = (points - origin) @ rot
    return np.stack(
        [cam.cam.fx * p[:, 0] / p[:, 2] + cam.cam.cx, cam.cam.fy * p[:, 1] / p[:, 2] + cam.cam.cy],
        1,
    )


def box_of(frame: CameraFrame, instance: int) -> tuple[np.ndarray, np.ndarray]:
    row = np.flatnonzero(frame.boxes[:, 0] == instance)
    assert row.size == 1, f"instance {instance} has no box: {frame.boxes}"
    return frame.boxes[row[0]], frame.box_flags[row[0]]


def test_boat_in_front_is_segmented_and_boxed() -> None:
    scene = scene_with({"b": (30.0, 0.0, BOAT)})
    cam, frame = shoot(scene)
    corners = scene.corners()[1]
    centre = project(cam, corners.mean(axis=0, keepdims=True))[0]
    u, v = int(centre[0]), int(centre[1])
    assert frame.segmentation[v, u] == CLASS_VESSEL and frame.instance[v, u] == 2
    box, flags = box_of(frame, 2)
    uv = project(cam, corners)
    full = (uv[:, 0].min(), uv[:, 1].min(), uv[:, 0].max(), uv[:, 1].max())
    assert box[1] == CLASS_VESSEL
    # the mask's box is the projected box, less the part of the hull under water (bottom)
    assert abs(box[2] - full[0]) <= 1 and abs(box[4] - full[2]) <= 1 and abs(box[3] - full[1]) <= 1
    assert full[1] < box[5] <= full[3] + 1
    assert flags.tolist() == [0, 0, 100]  # not truncated, not occluded, all of it seen


def test_boat_at_the_image_edge_is_truncated() -> None:
    edge_y = 28.0 * math.tan(math.radians(40.0))  # the left edge of an 80 deg view at 28 m
    _, frame = shoot(scene_with({"b": (30.0, edge_y, BOAT)}))
    box, flags = box_of(frame, 2)
    assert box[2] == 0 and flags[0] == 1


def test_boat_behind_another_is_occluded() -> None:
    alone = shoot(scene_with({"far": (30.0, 0.0, BOAT)}))[1]
    hidden = shoot(scene_with({"far": (30.0, 0.0, BOAT), "near": (15.0, 0.8, TALL)}))[1]
    assert box_of(alone, 2)[1][1] == 0
    assert box_of(hidden, 2)[1][1] == 1 and box_of(hidden, 3)[1][1] == 0


def test_depth_of_the_water_plane_is_exact() -> None:
    cam, frame = shoot(scene_with({}), mount_xyz=(0.0, 0.0, 1.5), mount_rpy_deg=(0, 30, 0))
    origin, rot = cam.pose(own_state())
    dirs = (cam.rays.astype(np.float64) @ rot.T).reshape(frame.height, frame.width, 3)
    water = frame.segmentation == CLASS_WATER
    assert water.mean() > 0.8  # the rest is beyond max_range_m: sky
    expected = origin[2] / -dirs[..., 2] * cam.rays[:, 2].reshape(frame.height, frame.width)
    np.testing.assert_allclose(frame.depth[water], expected[water], rtol=1e-4)
    assert np.isinf(frame.depth[frame.segmentation == CLASS_NONE]).all()


def test_normals_are_unit_and_face_the_camera() -> None:
    cam, frame = shoot(scene_with({"b": (30.0, 5.0, BOAT)}))
    n = frame.normals.astype(np.float64) / 127.0
    hit = frame.segmentation != CLASS_NONE
    np.testing.assert_allclose(np.linalg.norm(n[hit], axis=-1), 1.0, atol=0.02)
    facing = np.sum(n.reshape(-1, 3) * cam.rays, axis=1).reshape(hit.shape)
    assert (facing[hit] < 0.02).all()  # a visible surface faces the ray that sees it
    assert not n[~hit].any()


def contrast(rate: float) -> float:
    scene = scene_with({f"b{i}": (20.0 + 15 * i, -8.0 + 4 * i, BOAT) for i in range(5)})
    scene.rain_rate_mm_h = rate
    frame = shoot(scene)[1]
    boats = frame.color[frame.segmentation == CLASS_VESSEL].astype(np.float64)
    return float(np.median(np.linalg.norm(boats - VEIL, axis=1)))  # streak-proof: a median


def test_rain_lowers_contrast_monotonically() -> None:
    values = [contrast(r) for r in (0.0, 5.0, 20.0, 50.0)]
    assert all(a > b for a, b in itertools.pairwise(values)), values


def test_frames_are_deterministic_and_outputs_can_be_switched_off() -> None:
    scene = scene_with({"b": (30.0, 0.0, BOAT)})
    scene.rain_rate_mm_h = 10.0
    a, b = shoot(scene)[1], shoot(scene)[1]
    assert a.color.tobytes() == b.color.tobytes() and a.boxes.tobytes() == b.boxes.tobytes()
    off = shoot(scene, outputs={"color": False, "depth": False, "normals": False})[1]
    assert off.color.size == off.depth.size == off.normals.size == 0
    assert off.boxes.tobytes() == a.boxes.tobytes()


def test_a_camera_needs_the_scene() -> None:
    with pytest.raises(ValueError, match="scene"):
        CameraModel(CameraParams(), Mount(scene=None))


def test_projected_pixel_cull_gives_the_same_hits_as_the_full_test() -> None:
    boats = {f"b{i}": (8.0 + 12 * i, -10.0 + 5 * i, BOAT) for i in range(6)}
    boats["beside"] = (0.5, 3.0, BOAT)  # straddles the camera plane: every pixel is a candidate
    scene = scene_with(boats)
    cam, frame = shoot(scene)
    origin, rot = cam.pose(own_state())
    full = scene.cast(origin, np.dot(cam.rays, rot.T.astype(np.float32)), 1000.0)
    assert np.array_equal(frame.instance.ravel(), full.instance)
    np.testing.assert_allclose(frame.depth.ravel(), full.range * cam.rays[:, 2], rtol=1e-6)
