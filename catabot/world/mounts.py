"""A ray-casting sensor mounted inside its own vessel's shape is refused before the run.

Its every ray starts inside the hull and hits it from within: a camera inside the catamaran's
electronics box saw one "vessel" filling the image, 0.1 m away, in every frame, and the
dataset labelled it so. An IMU or GPS sits inside the boat, as real ones do: only the
sensors whose rays start at the mount are checked (LiDAR and camera `mount_xyz`, the
radar's antenna at `antenna_height_m` above the origin).

Inside is ray parity: a ray from the point crosses a closed surface an odd number of times.
It is asked along five rays in general directions and most must say so, so a ray grazing
an edge does not decide it.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from catabot.config.sensors import RadarParams
from catabot.errors import CataBotError
from catabot.world.shapes import ShapeMesh
from catabot.world.world import MountedSensor, World

F64 = NDArray[np.float64]


class MountInsideError(CataBotError, ValueError):
    """A LiDAR, radar or camera whose rays would start inside its own vessel."""


def ray_origin(sensor: MountedSensor) -> tuple[float, float, float] | None:
    """Where the sensor's rays start in its vessel's body frame; None: it casts none."""
    params = sensor.params
    if isinstance(params, RadarParams):
        return (0.0, 0.0, params.antenna_height_m)
    mount = getattr(params, "mount_xyz", None)
    return None if mount is None else (float(mount[0]), float(mount[1]), float(mount[2]))


# Five rays in general directions: one along an axis met a tapered bow's apex edge and
# counted it twice (the centre of every bundled hull came out "outside").
RAYS = np.array([(1.0, 0.31, 0.17), (-0.23, 1.0, 0.37), (0.29, -0.21, 1.0),
                 (-1.0, -0.41, 0.27), (0.19, 0.33, -1.0)])  # fmt: skip


def crossings(mesh: ShapeMesh, point: F64, direction: F64) -> int:
    """Triangles a ray from `point` along `direction` passes through: each triangle seen in
    axes (u, v, d), d along the ray, with the barycentric test in the (u, v) plane."""
    d = direction / np.linalg.norm(direction)
    u = np.cross(d, (0.0, 0.0, 1.0) if abs(d[2]) < 0.9 else (1.0, 0.0, 0.0))
    u /= np.linalg.norm(u)
    basis = np.stack([u, np.cross(d, u), d])  # rows: the new axes
    tri = (mesh.vertices[mesh.triangles] - point) @ basis.T  # (T, 3, 3), the point at 0
    a, b, c = tri[:, 0], tri[:, 1], tri[:, 2]
    d1, d2 = b - a, c - a
    det = d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]
    with np.errstate(divide="ignore", invalid="ignore"):  # edge-on triangles: NaN, no hit
        s = (-a[:, 0] * d2[:, 1] + a[:, 1] * d2[:, 0]) / det
        t = (-d1[:, 0] * a[:, 1] + d1[:, 1] * a[:, 0]) / det
        hit = (s >= 0) & (t >= 0) & (s + t <= 1)
        along = a[:, 2] + s * d1[:, 2] + t * d2[:, 2]
    return int(np.count_nonzero(hit & (along > 0)))


def inside(mesh: ShapeMesh, point: tuple[float, float, float]) -> bool:
    """Most of the rays cross the surface an odd number of times."""
    p = np.asarray(point, dtype=np.float64)
    odd = sum(crossings(mesh, p, ray) % 2 for ray in RAYS)
    return odd > len(RAYS) // 2


def check_mounts(world: World) -> None:
    """Refuse the first ray-casting sensor whose rays start inside its own vessel's shape,
    a radar below its shape's top: its level sweep would hit its own hull (at 0 m, 205
    of 240 beams returned the catamaran's own hulls, 2-10 mm off), and any below the water."""
    for i, vessel in enumerate(world.scenario.vessels):
        body = world.body(vessel.id)
        mesh = world.shapes[body.model_ref]
        for j, sensor in enumerate(s for s in world.sensors if s.vessel == vessel.id):
            origin = ray_origin(sensor)
            if origin is not None and origin[2] < 0.0:
                field = (
                    "antenna_height_m" if isinstance(sensor.params, RadarParams) else "mount_xyz"
                )
                raise MountInsideError(
                    f"vessels.{i}.sensors.{j} ({sensor.config.name}): its rays start at "
                    f"{list(origin)} ({field}), under water: z is up from {vessel.id}'s "
                    "waterline at rest, and the sensors model no view under the surface "
                    "(a LiDAR 1 m down saw rain and the seabed); mount it above z = 0"
                )
            if mesh is None or origin is None:
                continue
            if isinstance(sensor.params, RadarParams) and origin[2] <= mesh.hi[2]:
                raise MountInsideError(
                    f"vessels.{i}.sensors.{j} ({sensor.config.name}): antenna_height_m "
                    f"{origin[2]:g} is not above {vessel.id}'s own shape (model "
                    f"{body.model_ref!r}, up to z = {mesh.hi[2]:.2f} m): its level sweep would "
                    "hit its own hull; mount it higher"
                )
            if not inside(mesh, origin):
                continue
            raise MountInsideError(
                f"vessels.{i}.sensors.{j} ({sensor.config.name}): its rays start at "
                f"{list(origin)} (mount_xyz), inside {vessel.id}'s own shape (model "
                f"{body.model_ref!r}, up to z = {mesh.hi[2]:.2f} m): every ray would hit its own "
                "hull from within; mount it above the deck"
            )
