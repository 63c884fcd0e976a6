"""Bus messages into rerun, on the `sim_time` timeline: one logger for the live view and the
replay (so `run.rrd`, `catabot view RUN` and `catabot run --view` show the same things).

Per `BodyStates`: every body's pose as an instance of its model's mesh (one log call per
model and colour, not one per body: `static.body_groups`),
each scenario vessel's transform (its sensors hang below it, so a LiDAR scan is drawn from
the pose it was taken at; a radar's level frame is logged with it: catabot/ros2/frames.py)
and its speed and heading. At most every `TRAIL_S` of simulated
time: the vessels' positions for the trails and the closest approach between two vessels;
every `WATER_S`: the wave surface around the first vessel. Sensors: LiDAR points coloured by
intensity (rain in magenta), radar sector and echoes in 3D and on the north-up minimap,
camera images with segmentation and boxes, IMU series. The live view may skip any message
(it drops rather than waits); nothing here assumes it saw the previous one.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np
import rerun as rr

from catabot.bus.messages import LABEL_CLASSES, BodyStates, ImuSample, LidarScan, RadarSweep
from catabot.ros2.frames import mount, stabilised
from catabot.world import rotations
from catabot.world.terrain_grid import grid_triangles
from catabot.world.world import MountedSensor, World
from services.viewer import palette, paths
from services.viewer.static import body_groups, log_static, setpoint_lines

TRAIL_S = 0.2
WATER_S = 0.25
WATER_HALF_M, WATER_CELLS = 80.0, 48


class RunLogger:
    def __init__(self, rec: rr.RecordingStream, world: World, *, scripts: bool = True) -> None:
        self.rec, self.world = rec, world
        self.groups = body_groups(world)
        self.vessels = len(world.vessels)
        self.own = [world.body(v.id) for v in world.scenario.vessels]
        self.radars = [s for s in world.sensors if stabilised(s)]  # frames that move: logged
        self.radar_rows = [world.body(s.vessel).row for s in self.radars]
        self.waves = world.waves
        self._last = {"trail": -math.inf, "water": -math.inf}
        self._closest = math.inf
        self._named: set[str] = set()  # vessels whose set-point lines are named
        log_static(rec, world, scripts=scripts)
        self._series_names()
        if self.waves.is_calm:
            self._calm_water()

    def time(self, stamp_ns: int) -> None:
        self.rec.set_time("sim_time", duration=np.timedelta64(int(stamp_ns), "ns"))

    def _series_names(self) -> None:
        """Line names carry their owner: a view holds one quantity for every owner."""
        suffixes = {
            "speed": [""], "heading": [""], "lidar": [" returns", " rain returns"],
            "imu_accel": [" x [m/s²]", " y [m/s²]", " z [m/s²]"],
            "imu_gyro": [" x [rad/s]", " y [rad/s]", " z [rad/s]"],
        }  # fmt: skip
        owners: dict[str, list[str]] = {
            "speed": [b.id for b in self.own], "heading": [b.id for b in self.own],
            "imu_accel": self._owners("imu"), "imu_gyro": self._owners("imu"),
            "lidar": self._owners("lidar"),
        }  # fmt: skip
        for quantity, who in owners.items():
            for owner in who:
                lines = rr.SeriesLines(names=[owner + end for end in suffixes[quantity]])
                self.rec.log(paths.series(quantity, owner), lines, static=True)
        self.rec.log(paths.RTF, rr.SeriesLines(names=["real-time factor"]), static=True)
        self.rec.log(paths.CLOSEST, rr.SeriesLines(names=["closest approach [m]"]), static=True)

    def _owners(self, kind: str) -> list[str]:
        return [f"{s.vessel}.{s.config.name}" for s in self.world.sensors if s.config.type == kind]

    def states(self, batch: BodyStates) -> None:
        self.time(batch.stamp_ns)
        pos, quat = aligned(batch.position), aligned(batch.orientation)
        if rotations.normalised_matrices(quat) is None:
            return  # a non-finite pose (a diverged body): nothing sensible to draw
        for group in self.groups:
            poses = rr.InstancePoses3D(translations=pos[group.rows], quaternions=quat[group.rows])
            self.rec.log(group.path, poses)
        yaw = rotations.yaw_of_quaternions(quat[[b.row for b in self.own]])
        for body, heading in zip(self.own, yaw.tolist(), strict=True):
            r = body.row
            pose = rr.Transform3D(translation=pos[r], quaternion=rr.Quaternion(xyzw=quat[r]))
            self.rec.log(paths.vessel(body.id), pose)
            speed = math.hypot(*np.asarray(batch.linear_velocity[r, :2]).tolist())
            self.rec.log(paths.series("speed", body.id), rr.Scalars(speed))
            compass = (90.0 - math.degrees(heading)) % 360.0
            self.rec.log(paths.series("heading", body.id), rr.Scalars(compass))
        self._radar_frames(quat)
        if self._due("trail", batch.stamp_ns, TRAIL_S):
            self._trails(pos[: self.vessels])
        if not self.waves.is_calm and self.own and self._due("water", batch.stamp_ns, WATER_S):
            self._water(pos[self.own[0].row], batch.stamp_ns)

    def _radar_frames(self, quat: np.ndarray) -> None:
        """Each radar's frame on its vessel: level at the antenna, turned with the heading."""
        level = [rotations.levelling(q) for q in quat[self.radar_rows].tolist()]
        for sensor, turn in zip(self.radars, level, strict=True):
            at = mount(sensor)[0]
            pose = rr.Transform3D(translation=at, quaternion=rr.Quaternion(xyzw=turn))
            self.rec.log(paths.sensor(sensor.vessel, sensor.config.name), pose)

    def _due(self, what: str, stamp_ns: int, every_s: float) -> bool:
        """Whether `every_s` of simulated time passed since `what` was last logged."""
        if stamp_ns / 1e9 - self._last[what] < every_s - 1e-9:
            return False
        self._last[what] = stamp_ns / 1e9
        return True

    def _trails(self, pos: np.ndarray) -> None:
        colors = np.array(
            [palette.EGO] * len(self.own) + [palette.BOAT] * (len(pos) - len(self.own))
        )
        self.rec.log(paths.TRAILS, rr.Points3D(pos, colors=colors, radii=0.25))
        if len(pos) >= 2:
            gap = np.linalg.norm(pos[:, None, :2] - pos[None, :, :2], axis=-1)
            np.fill_diagonal(gap, np.inf)
            self.rec.log(paths.CLOSEST, rr.Scalars(float(gap.min())))

    def _water(self, centre: np.ndarray, stamp_ns: int) -> None:
        axis = np.linspace(-WATER_HALF_M, WATER_HALF_M, WATER_CELLS + 1)
        gx, gy = np.meshgrid(centre[0] + axis, centre[1] + axis)
        gz = self.waves.height(gx, gy, stamp_ns / 1e9)
        vertices = np.stack([gx.ravel(), gy.ravel(), gz.ravel()], axis=1)
        triangles = grid_triangles(WATER_CELLS + 1, WATER_CELLS + 1)
        shade = np.clip(0.5 + gz.ravel() / max(2 * float(np.abs(gz).max()), 1e-6), 0, 1)
        colors = np.rint(np.outer(0.6 + 0.4 * shade, palette.WATER[:3])).astype(np.uint8)
        mesh = rr.Mesh3D(
            vertex_positions=vertices, triangle_indices=triangles, vertex_colors=colors
        )
        self.rec.log(paths.WATER, mesh)

    def _calm_water(self) -> None:
        """A flat sea over the terrain (or 1 km around the origin), once."""
        t = self.world.terrain
        (x0, y0), (x1, y1) = ((0.0, 0.0), t.size_m) if t is not None else ((-500, -500), (500, 500))
        vertices = np.array([[x0, y0, 0.0], [x1, y0, 0.0], [x1, y1, 0.0], [x0, y1, 0.0]])
        mesh = rr.Mesh3D(vertex_positions=vertices, triangle_indices=[[0, 1, 2], [0, 2, 3]],
                         albedo_factor=palette.WATER)  # fmt: skip
        self.rec.log(paths.WATER, mesh, static=True)

    def lidar(self, sensor: MountedSensor, scan: LidarScan) -> None:
        self.time(scan.stamp_ns)
        colors = palette.intensity_colors(scan.intensity, scan.is_rain)
        path = paths.sensor(sensor.vessel, sensor.config.name)
        self.rec.log(path, rr.Points3D(aligned(scan.points), colors=colors, radii=0.06))
        rain = int(np.count_nonzero(scan.is_rain))
        owner = f"{sensor.vessel}.{sensor.config.name}"
        self.rec.log(paths.series("lidar", owner), rr.Scalars([len(scan.points), rain]))

    def radar(self, sensor: MountedSensor, sweep: RadarSweep) -> None:
        self.time(sweep.stamp_ns)
        step = (sweep.azimuth_start_rad - sweep.azimuth_end_rad) / max(sweep.beams - 1, 1)
        arc = np.linspace(sweep.azimuth_start_rad, sweep.azimuth_end_rad, max(sweep.beams, 2))
        edge = np.stack([np.cos(arc), np.sin(arc), np.zeros_like(arc)], axis=1) * sweep.range_m
        sector = np.concatenate([[[0.0, 0.0, 0.0]], edge, [[0.0, 0.0, 0.0]]])
        path = paths.sensor(sensor.vessel, sensor.config.name)
        self.rec.log(
            path + "/sector", rr.LineStrips3D([sector], colors=[palette.RADAR], radii=0.15)
        )
        beam, cell = np.nonzero(sweep.intensity)
        r = (cell + 0.5) * (sweep.range_m / sweep.intensity.shape[1])
        az = sweep.azimuth_start_rad - step * beam
        strength = sweep.intensity[beam, cell]
        colors = palette.radar_colors(strength)
        echoes = np.stack([r * np.cos(az), r * np.sin(az), np.zeros_like(r)], axis=1)
        self.rec.log(path + "/echoes", rr.Points3D(echoes, colors=colors, radii=0.5))
        bearing = sweep.heading_rad + az  # ENU, counter-clockwise from east
        screen = np.stack([r * np.cos(bearing), -r * np.sin(bearing)], axis=1)  # north up
        dots = rr.Points2D(screen, colors=colors, radii=sweep.range_m / 200)
        self.rec.log(paths.minimap(sensor.vessel, sensor.config.name) + "/echoes", dots)

    def camera(
        self, sensor: MountedSensor, stamp_ns: int, color: np.ndarray | None,
        segmentation: np.ndarray | None, boxes: np.ndarray | None,
    ) -> None:  # fmt: skip
        """One frame: colour, class image (overlaid) and boxes [instance, class, x0, y0, x1, y1)."""
        self.time(stamp_ns)
        path = paths.sensor(sensor.vessel, sensor.config.name)
        if color is not None and color.size:
            self.rec.log(path + "/color", rr.Image(aligned(color)))
        if segmentation is not None and segmentation.size:
            classes = rr.SegmentationImage(aligned(segmentation), opacity=0.35)
            self.rec.log(path + "/segmentation", classes)
        if boxes is not None:
            cls = boxes[:, 1].astype(np.int64)
            labels = [f"{_name(c)} {int(i)}" for c, i in zip(cls, boxes[:, 0], strict=True)]
            two_d = rr.Boxes2D(array=aligned(boxes[:, 2:6]), array_format=rr.Box2DFormat.XYXY,
                               class_ids=cls, labels=labels)  # fmt: skip
            self.rec.log(path + "/boxes", two_d)

    def imu(self, sensor: MountedSensor, samples: Sequence[ImuSample]) -> None:
        """Many samples in one call a series (100 Hz IMU rows, one Python call each, were
        most of the live view's CPU)."""
        if not samples:
            return
        owner = f"{sensor.vessel}.{sensor.config.name}"
        stamps = np.array([s.stamp_ns for s in samples], dtype="timedelta64[ns]")
        when = [rr.TimeColumn("sim_time", duration=stamps)]
        for kind, field in (("imu_accel", "linear_acceleration"), ("imu_gyro", "angular_velocity")):
            values = np.array([getattr(s, field) for s in samples], dtype=np.float64)
            columns = rr.Scalars.columns(scalars=values)
            self.rec.send_columns(paths.series(kind, owner), when, columns)

    def setpoints(
        self, vessel: str, stamps_ns: Sequence[int], twists: Sequence[tuple[float, float]]
    ) -> None:
        """Twist set-points (surge, yaw rate) a vessel was given by a stack, an outside client
        or the traffic: run.rrd had only a script's, so a navigator's panel stayed empty."""
        if not len(stamps_ns):
            return
        path = paths.series("setpoint", vessel)
        if vessel not in self._named:
            self._named.add(vessel)
            self.rec.log(path, setpoint_lines(vessel), static=True)
        when = [rr.TimeColumn("sim_time", duration=np.array(stamps_ns, dtype="timedelta64[ns]"))]
        values = np.array(twists, dtype=np.float64).reshape(-1, 2)
        self.rec.send_columns(path, when, rr.Scalars.columns(scalars=values))

    def thrust(self, vessel: str, stamp_ns: int, thrust: tuple[float, ...]) -> None:
        """A thrust command from the bus (a controller or an outside client)."""
        self.time(stamp_ns)
        self.rec.log(paths.series("thrust", vessel), rr.Scalars(thrust))

    def rtf(self, stamp_ns: int, factor: float) -> None:
        """The real-time factor (live only: it is wall-clock data, never recorded)."""
        self.time(stamp_ns)
        self.rec.log(paths.RTF, rr.Scalars(factor))

    def metrics(self, stamp_ns: int, metrics: dict[str, Any]) -> None:
        """metrics.json as a table: the scenario vessels, then the closest approach."""
        self.time(stamp_ns)
        text = metrics_markdown(metrics, [b.id for b in self.own])
        self.rec.log(paths.METRICS, rr.TextDocument(text, media_type=rr.MediaType.MARKDOWN))


def metrics_markdown(metrics: dict[str, Any], vessels: list[str]) -> str:
    rows = [
        "| vessel | distance [m] | top speed [m/s] | final position [m] |",
        "|---|---:|---:|---|",
    ]
    for vid in vessels:
        m = metrics.get("vessels", {}).get(vid)
        if m:
            final = ", ".join(f"{v:.1f}" for v in (m.get("final_position_m") or [])[:2])
            distance, speed = m["distance_m"], m["max_speed_mps"]
            rows.append(f"| {vid} | {distance:.1f} | {speed:.2f} | ({final}) |")
    close = metrics.get("closest_approach")
    if close:
        pair, when = " and ".join(close["vessels"]), close["stamp_ns"] / 1e9
        rows.append(f"\nClosest approach: **{close['distance_m']:.2f} m**, {pair} at {when:.2f} s")
    return "\n".join(rows)


def aligned(values: Any) -> np.ndarray:
    """An array rerun can take: decoded bus arrays are views into the payload at any byte
    offset, and arrow refuses (panics on) a float buffer that is not aligned."""
    return np.require(values, requirements=("C", "A"))


def _name(class_id: int) -> str:
    return LABEL_CLASSES[class_id] if 0 <= class_id < len(LABEL_CLASSES) else str(class_id)
