"""Pinhole camera: colour, depth, normals, segmentation and 2D boxes from ONE ray cast.

Every output is a function of the same per-pixel first hits, so the frame costs one cast
(the dominant cost, ~7 M rays/s) plus vectorised post-processing; switching outputs off
skips only their post-processing, and segmentation is always cast because the boxes and the
shading need the class of each hit.

Frames. The mount (`mount_xyz`, `mount_rpy_deg`) places a camera body frame on the vessel in
FLU: rpy = 0 looks along the bow; positive pitch looks down (a rotation about +y turns +x
toward -z). Images are in the ROS optical frame: z forward, x right, y down; pixel (u, v) has
its centre at (u + 0.5, v + 0.5) and square pixels with fx = (W / 2) / tan(hfov / 2).
Depth is the distance along the optical axis (range x cos of the angle off-axis); normals are
in the optical frame. Hits beyond `max_range_m` are sky (class 0, depth inf).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import ClassVar, Protocol

import numpy as np
from numpy.typing import NDArray

from catabot.bus.messages import CameraFrame, Message, VesselState
from catabot.config.sensors import CameraParams
from catabot.world import rotations, seeding
from services.sensors import camera_boxes as cb
from services.sensors.camera_shading import rain_streaks, rain_veil, shade
from services.sensors.common import SensorError, rotation_from_quaternion
from services.sensors.mount import Mount
from services.sensors.scene import Body, Hits

F64 = NDArray[np.float64]
F32 = NDArray[np.float32]
OPTICAL_TO_BODY = np.array([[0.0, 0.0, 1.0], [-1.0, 0.0, 0.0], [0.0, -1.0, 0.0]])
"""v_body = OPTICAL_TO_BODY @ v_optical: optical z -> forward, x -> right (-y), y -> down."""
EMPTY = np.empty(0, dtype=np.uint8)


class CastScene(Protocol):
    """What a camera needs of the scene (services/sensors/scene.py; tests pass fakes)."""

    bodies: list[Body]
    rain_rate_mm_h: float  # the scenario's rain (mm/h): veils and streaks the colour image

    def cast(
        self,
        origins: np.ndarray,
        directions: np.ndarray,
        max_range: float,
        pairs: tuple[NDArray[np.intp], NDArray[np.intp]] | None = None,
        *,
        silhouettes: bool = False,
    ) -> Hits: ...

    def corners(self) -> F64: ...

    def outlines(self, rows: NDArray[np.intp]) -> list[tuple[NDArray[np.intp], F64]]: ...


def rpy_matrix(rpy_deg: Sequence[float]) -> F64:
    """Rz(yaw) @ Ry(pitch) @ Rx(roll) of (roll, pitch, yaw) in degrees."""
    roll, pitch, yaw = rpy_deg
    return rotations.rpy(roll, pitch, yaw)


def pinhole(width: int, height: int, hfov_deg: float) -> cb.Pinhole:
    f = (width / 2) / math.tan(math.radians(hfov_deg) / 2)
    return cb.Pinhole(width, height, f, f, width / 2, height / 2)


def pixel_rays(cam: cb.Pinhole) -> F32:
    """Unit ray directions (H * W, 3) in the optical frame, row-major from the top-left."""
    u = (np.arange(cam.width) + 0.5 - cam.cx) / cam.fx
    v = (np.arange(cam.height) + 0.5 - cam.cy) / cam.fy
    uu, vv = np.meshgrid(u, v)
    rays = np.stack([uu, vv, np.ones_like(uu)], axis=-1).reshape(-1, 3)
    return (rays / np.linalg.norm(rays, axis=1, keepdims=True)).astype(np.float32)


class CameraModel:
    """One camera on one vessel; deterministic (rain streaks come from its own generator)."""

    message: ClassVar[type[Message]] = CameraFrame

    def __init__(self, params: CameraParams, mount: Mount) -> None:
        scene: CastScene | None = mount.scene
        seed, name = mount.seed, mount.name
        if scene is None:
            raise SensorError(f"camera {name!r} needs the ray-casting scene")
        self.params, self.scene, self.name = params, scene, name
        self.cam = pinhole(params.width, params.height, params.hfov_deg)
        self.rays = pixel_rays(self.cam)
        self.mount_rot = rpy_matrix(params.mount_rpy_deg) @ OPTICAL_TO_BODY
        self.mount_pos = np.asarray(params.mount_xyz, dtype=np.float64)
        self._rng = seeding.rng(seed, name)
        self._row_of: NDArray[np.intp] | None = None  # scene row by instance, on first use

    def pose(self, state: VesselState) -> tuple[F64, F64]:
        """Optical frame in `map`: origin (3,) and rotation (v_map = R @ v_optical)."""
        body = rotation_from_quaternion(state.orientation)
        origin = np.asarray(state.position, dtype=np.float64) + body @ self.mount_pos
        return origin, body @ self.mount_rot

    def sample(self, state: VesselState, *, tick: int, stamp_ns: int) -> CameraFrame:
        origin, rot = self.pose(state)
        dirs = np.dot(self.rays, rot.T.astype(np.float32))
        corners_cam = (self.scene.corners() - origin) @ rot
        pairs = cb.candidate_rays(corners_cam, self.cam)  # each box against its own pixels
        hits = self.scene.cast(origin, dirs, self.params.max_range_m, pairs, silhouettes=True)
        return self.frame(hits, dirs, origin, rot, tick=tick, stamp_ns=stamp_ns)

    def frame(
        self, hits: Hits, dirs: F32, origin: F64, rot: F64, *, tick: int, stamp_ns: int
    ) -> CameraFrame:
        """Every enabled output derived from the one cast."""
        p, h, w = self.params, self.params.height, self.params.width
        out = p.outputs
        depth = (hits.range * self.rays[:, 2]).reshape(h, w) if out.depth else EMPTY
        normals = EMPTY
        if out.normals:
            cam_n = np.dot(hits.normal, rot.astype(np.float32))
            np.multiply(cam_n, np.float32(127.0), out=cam_n)
            normals = np.rint(cam_n, out=cam_n).astype(np.int8).reshape(h, w, 3)
        seg = hits.cls.reshape(h, w)
        inst = hits.instance.reshape(h, w)
        color = self._color(hits, dirs, float(origin[2])) if out.color else EMPTY
        boxes, box_flags = self._boxes(seg, inst, origin, rot, hits)
        return CameraFrame(
            tick=tick,
            stamp_ns=stamp_ns,
            width=w,
            height=h,
            hfov_rad=math.radians(p.hfov_deg),
            objects=int(boxes.shape[0]),
            color=color,
            depth=depth,
            normals=normals,
            segmentation=seg if out.segmentation else EMPTY,
            instance=inst.astype(np.uint16) if out.segmentation else EMPTY,
            boxes=boxes,
            box_flags=box_flags,
        )

    def _color(self, hits: Hits, dirs: F32, origin_z: float) -> NDArray[np.uint8]:
        p = self.params
        planes = shade(hits.cls, hits.instance, hits.range, hits.normal, dirs, origin_z)
        distance = np.minimum(hits.range, np.float32(p.max_range_m))
        planes = rain_veil(planes, distance, self.scene.rain_rate_mm_h)
        planes = planes.reshape(3, p.height, p.width)
        rain_streaks(planes, self.scene.rain_rate_mm_h, self._rng)
        rgb = np.empty((p.height, p.width, 3), dtype=np.uint8)
        np.copyto(rgb.transpose(2, 0, 1), planes, casting="unsafe")  # all blends within 0..255
        return rgb

    def _boxes(
        self, seg: NDArray[np.uint8], inst: NDArray[np.int32], origin: F64, rot: F64, hits: Hits
    ) -> tuple[F32, NDArray[np.uint8]]:
        """(K, 6) [instance, class, x0, y0, x1, y1] and (K, 3) [truncated, occluded,
        visible %]. An instance that is no body of the scene keeps its mask's box and is
        never occluded."""
        vis = cb.visible_boxes(inst, seg)
        if vis.ids.size == 0:
            return np.empty((0, 6), np.float32), np.empty((0, 3), np.uint8)
        if self._row_of is None:
            self._row_of = _rows_by_instance(self.scene.bodies)
        rows = self._row_of[np.minimum(vis.ids, self._row_of.size - 1)]
        known = np.flatnonzero(rows >= 0)
        full, behind = vis.box.copy(), np.zeros(vis.ids.size, dtype=bool)
        for sel, points in self.scene.outlines(rows[known]):  # one group per kind of shape
            box, back = cb.projected_boxes((points - origin) @ rot, self.cam)
            full[known[sel]], behind[known[sel]] = box, back
        silhouette = vis.count.copy()
        if hits.silhouette is not None:
            silhouette[known] = hits.silhouette[rows[known]]
        p = self.params
        flags = cb.flags(vis, full, behind, silhouette, cam=self.cam, fraction=p.occluded_fraction)
        table = np.column_stack([vis.ids, vis.cls, vis.box]).astype(np.float32)
        return table, flags


def _rows_by_instance(bodies: Sequence[Body]) -> NDArray[np.intp]:
    """Scene row of each instance id (-1: none; the last entry stands for every larger id)."""
    ids = np.array([b.instance for b in bodies], dtype=np.intp)
    table = np.full(int(ids.max(initial=0)) + 2, -1, dtype=np.intp)
    table[ids] = np.arange(ids.size)
    return table
