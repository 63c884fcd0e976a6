"""A ray-casting sensor mounted inside its own vessel's shape is refused before the run.

Its every ray starts inside the hull and hits it from within: a camera inside the catamaran's
electronics box saw one "vessel" filling the image, 0.1 m away, in every frame, and the
dataset labelled it so. An IMU or GPS sits inside the boat, as real ones do: only the
sensors whose rays start at the mount are checked (LiDAR and camera `mount_xyz`, the
radar's antenna at `antenna_height_m` above the origin).

Inside is ray parity: a ray from the point crosses a closed surface an odd number of times.
It is asked along x, y and z and all three must agree, so an open mesh (a hull without a
deck) or a ray grazing an edge answers "not inside" rather than refusing a good mount.
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


def crossings(mesh: ShapeMesh, point: F64, axis: int) -> int:
    """Triangles a ray from `point` along +`axis` passes through (projected barycentrics)."""
    u, v = [a for a in range(3) if a != axis]
    tri = mesh.vertices[mesh.triangles]  # (T, 3, 3)
    a, b, c = tri[:, 0], tri[:, 1], tri[:, 2]
    d1, d2 = b - a, c - a
    det = d1[:, u] * d2[:, v] - d1[:, v] * d2[:, u]
    px, py = point[u] - a[:, u], point[v] - a[:, v]
    with np.errstate(divide="ignore", invalid="ignore"):  # edge-on triangles: NaN, no hit
        s = (px * d2[:, v] - py * d2[:, u]) / det
        t = (d1[:, u] * py - d1[:, v] * px) / det
        hit = (s >= 0) & (t >= 0) & (s + t <= 1)
        along = a[:, axis] + s * d1[:, axis] + t * d2[:, axis]
    return int(np.count_nonzero(hit & (along > point[axis])))


def inside(mesh: ShapeMesh, point: tuple[float, float, float]) -> bool:
    p = np.asarray(point, dtype=np.float64)
    return all(crossings(mesh, p, axis) % 2 == 1 for axis in range(3))


def check_mounts(world: World) -> None:
    """Refuse the first ray-casting sensor whose rays start inside its own vessel's shape."""
    for i, vessel in enumerate(world.scenario.vessels):
        body = world.body(vessel.id)
        mesh = world.shapes[body.model_ref]
        for j, sensor in enumerate(s for s in world.sensors if s.vessel == vessel.id):
            origin = ray_origin(sensor)
            if mesh is None or origin is None or not inside(mesh, origin):
                continue
            where = "antenna_height_m" if isinstance(sensor.params, RadarParams) else "mount_xyz"
            raise MountInsideError(
                f"vessels.{i}.sensors.{j} ({sensor.config.name}): its rays start at "
                f"{list(origin)} ({where}), inside {vessel.id}'s own shape (model "
                f"{body.model_ref!r}, up to z = {mesh.hi[2]:.2f} m): every ray would hit its own "
                "hull from within; mount it above the deck"
            )
