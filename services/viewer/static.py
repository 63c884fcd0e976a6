"""What the viewer logs once, from the resolved World: terrain, body shapes, sensor mounts.

Everything here is static (timeless) in rerun: the terrain mesh with its height colours,
each model's shape as a mesh, once per colour it is drawn in (catabot/world/shapes.py; the
hull box for a model without one), whose instances the logger poses per tick (rerun's
InstancePoses3D: one log call per model and colour, not per body), each sensor's mount
under its vessel (LiDAR frames, each camera's pinhole in the ROS optical frame; a radar's
level frame turns against its hull, so the logger logs it with every state),
the radar screens' range rings, the label classes' names and colours, and the scripted
commands (known from the scenario before the run starts).
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import rerun as rr
from numpy.typing import NDArray

from catabot.config.sensors import CameraParams, LidarParams, RadarParams
from catabot.world import rotations
from catabot.world.shape_parts import box_mesh
from catabot.world.shapes import ShapeMesh
from catabot.world.terrain_grid import auto_resolution
from catabot.world.world import Body, MountedSensor, World
from services.viewer import palette, paths

TERRAIN_TRIANGLES = 200_000  # a viewer mesh: enough to read the shore, light to send
OPTICAL_TO_BODY = np.array([[0.0, 0.0, 1.0], [-1.0, 0.0, 0.0], [0.0, -1.0, 0.0]])
"""ROS optical frame (z forward, x right, y down) into the camera's FLU frame (DESIGN.md §8)."""


def log_static(rec: rr.RecordingStream, world: World, *, scripts: bool) -> None:
    """`scripts`: draw the scenario's scripted commands. The live view needs them (physics
    follows a script without a word on the bus); a replay does not, since run.mcap holds
    them as the commands they are, and drawing both doubled every scripted point."""
    rec.log(paths.WORLD, rr.ViewCoordinates.RIGHT_HAND_Z_UP, static=True)
    rec.log(paths.WORLD, rr.AnnotationContext(palette.class_table()), static=True)
    rec.log("minimap", rr.AnnotationContext(palette.class_table()), static=True)
    _terrain(rec, world)
    _bodies(rec, world)
    for sensor in world.sensors:
        _mount(rec, sensor)
    for body in world.vessels[: len(world.scenario.vessels)] if scripts else []:
        _script(rec, body)


def _terrain(rec: rr.RecordingStream, world: World) -> None:
    terrain = world.terrain
    if terrain is None:
        return
    z = terrain.elevation_m
    res = auto_resolution(z.shape, terrain.metres_per_pixel, TERRAIN_TRIANGLES)
    vertices, triangles = terrain.mesh(res)
    colors = palette.terrain_colors(vertices[:, 2], float(z.min()), float(z.max()))
    mesh = rr.Mesh3D(vertex_positions=vertices, triangle_indices=triangles, vertex_colors=colors)
    rec.log(paths.TERRAIN, mesh, static=True)


@dataclass(frozen=True)
class BodyGroup:
    """Bodies drawn alike (one model in one colour): their entity and their rows."""

    path: str
    rows: NDArray[np.intp]
    mesh: ShapeMesh
    color: tuple[int, int, int]


def body_groups(world: World) -> list[BodyGroup]:
    """The bodies by model and role (scenario vessel, traffic boat, buoy: its colour), in
    order of first row; each group's entity is `world/bodies/<role>-<model file name>`
    (with its number where two model files share a name)."""
    scenario = {v.id for v in world.scenario.vessels}
    roles = {"vessel": palette.EGO, "boat": palette.BOAT, "buoy": palette.BUOY}
    rows: dict[tuple[str, str], list[int]] = {}
    for b in world.bodies:  # once, at start
        key = ("vessel" if b.id in scenario else b.kind, b.model_ref)
        rows.setdefault(key, []).append(b.row)
    groups: list[BodyGroup] = []
    for (role, ref), members in rows.items():
        body = world.bodies[members[0]]
        mesh = world.shapes[ref] or ShapeMesh(*box_mesh(*body.model.hull_box()))
        name = f"{role}-{re.sub(r'[^A-Za-z0-9_]+', '_', Path(ref).stem)}"
        path = paths.bodies(name)
        if any(g.path == path for g in groups):
            path = paths.bodies(f"{name}-{len(groups)}")
        groups.append(BodyGroup(path, np.array(members, np.intp), mesh, roles[role]))
    return groups


def _bodies(rec: rr.RecordingStream, world: World) -> None:
    """Each group's mesh, flat shaded: every triangle its own vertices and face normal."""
    for group in body_groups(world):
        corners = group.mesh.vertices[group.mesh.triangles]  # (T, 3, 3)
        normal = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
        normal /= np.linalg.norm(normal, axis=1, keepdims=True)
        mesh = rr.Mesh3D(
            vertex_positions=corners.reshape(-1, 3),
            vertex_normals=np.repeat(normal, 3, axis=0),
            triangle_indices=np.arange(corners.shape[0] * 3).reshape(-1, 3),
            albedo_factor=(*group.color, 255),
        )
        rec.log(group.path, mesh, static=True)


def _mount(rec: rr.RecordingStream, sensor: MountedSensor) -> None:
    path = paths.sensor(sensor.vessel, sensor.config.name)
    params = sensor.params
    if isinstance(params, LidarParams):
        rot = rotations.rpy(0.0, params.mount_pitch_deg, params.mount_yaw_deg)
        rec.log(path, rr.Transform3D(translation=params.mount_xyz, mat3x3=rot), static=True)
    elif isinstance(params, RadarParams):  # its frame moves with the heading: logger.py
        rings = [_circle(params.range_m * k / 4) for k in (1, 2, 3, 4)]
        r = params.range_m
        cross = [np.array([(-r, 0.0), (r, 0.0)]), np.array([(0.0, -r), (0.0, r)])]
        screen = rr.LineStrips2D([*rings, *cross], colors=[(30, 110, 40)], radii=0.004 * r)
        minimap = paths.minimap(sensor.vessel, sensor.config.name)
        rec.log(minimap + "/rings", screen, static=True)
        north = rr.Points2D([(0, -1.04 * r)], labels=["N"], colors=[palette.RADAR], radii=0.01 * r)
        rec.log(minimap + "/north", north, static=True)
    elif isinstance(params, CameraParams):
        rot = rotations.rpy(*params.mount_rpy_deg) @ OPTICAL_TO_BODY
        rec.log(path, rr.Transform3D(translation=params.mount_xyz, mat3x3=rot), static=True)
        focal = (params.width / 2) / math.tan(math.radians(params.hfov_deg) / 2)
        pinhole = rr.Pinhole(
            focal_length=focal,
            width=params.width,
            height=params.height,
            camera_xyz=rr.ViewCoordinates.RDF,
            image_plane_distance=4.0,
        )
        rec.log(path, pinhole, static=True)


def _circle(radius: float, n: int = 120) -> np.ndarray:
    a = np.linspace(0.0, 2 * math.pi, n + 1)
    return np.stack([radius * np.cos(a), radius * np.sin(a)], axis=1)


def _script(rec: rr.RecordingStream, body: Body) -> None:
    """A scripted vessel's commands as step series: thrust per thruster, twist set-points."""
    thrust = [(s.t_s, s.thrust) for s in body.script if s.thrust is not None]
    twist = [(s.t_s, s.twist) for s in body.script if s.twist is not None]
    step = rr.components.InterpolationMode.StepAfter
    if thrust:
        n = max(len(t) for _, t in thrust)
        names = [f"{body.id} thruster {i}" for i in range(n)]
        rec.log(paths.series("thrust", body.id), rr.SeriesLines(names=names,
                interpolation_mode=step), static=True)  # fmt: skip
        values = np.array([[*t, *[np.nan] * (n - len(t))] for _, t in thrust])
        _columns(rec, paths.series("thrust", body.id), [t for t, _ in thrust], values)
    if twist:
        rec.log(paths.series("setpoint", body.id), setpoint_lines(body.id), static=True)
        values = np.array([[t.surge_mps, t.yaw_rate_radps] for _, t in twist])
        _columns(rec, paths.series("setpoint", body.id), [t for t, _ in twist], values)


def setpoint_lines(vessel: str) -> rr.SeriesLines:
    """A vessel's twist set-points, as steps: a script's here, every other's (a stack's, the
    traffic's) in logger.py."""
    names = [f"{vessel} surge [m/s]", f"{vessel} yaw rate [rad/s]"]
    return rr.SeriesLines(names=names, interpolation_mode=rr.components.InterpolationMode.StepAfter)


def _columns(rec: rr.RecordingStream, path: str, t_s: list[float], values: np.ndarray) -> None:
    times = rr.TimeColumn("sim_time", duration=np.array(t_s, dtype=np.float64))
    scalars = rr.Scalars.columns(scalars=values.ravel()).partition([values.shape[1]] * len(t_s))
    rec.send_columns(path, indexes=[times], columns=scalars)
