"""ROS 2 topic names and frame ids of a world: one place, used by the recorder and the gateway.

Each vessel (traffic boats included) has a namespace, `/<id>` unless `ros.namespaces` says
otherwise (`/` puts a single robot at the root, as most ROS stacks expect: `/odom`,
`/cmd_vel`, `base_link`). Its frames are the namespace without the leading '/' as a prefix:
`ego/base_link`, `ego/lidar`, `ego/cam_optical`. World-wide topics are at the root:
`/tf`, `/tf_static`, `/clock`, `/buoys`.

Per vessel (under its namespace): `odom`; `cmd_vel`, `thrust`, `waypoints` (in); per sensor
`<sensor>/imu`, `<sensor>/fix`, `<sensor>/points` (LiDAR, radar), `<sensor>/ppi` (radar),
`<sensor>/image_raw`, `depth`, `segmentation`, `instance`, `normals`, `camera_info`.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from catabot.config.ros import RosConfig
from catabot.ros2 import types
from catabot.world.world import MountedSensor, World

MAP = "map"
TF = "/tf"
TF_STATIC = "/tf_static"
CLOCK = "/clock"
BUOYS = "/buoys"

CAMERA_OUTPUTS = {  # CameraParams.outputs flag -> (topic, encoding) of its images
    "color": (("image_raw", "rgb8"),),
    "depth": (("depth", "32FC1"),),
    "segmentation": (("segmentation", "mono8"), ("instance", "mono16")),
    "normals": (("normals", "rgb8"),),
}
COMMANDS = {"cmd_vel": types.TWIST, "thrust": types.FLOAT64_ARRAY, "waypoints": types.PATH}


def join(namespace: str, *parts: str) -> str:
    """A fully qualified topic: '/' + the namespace's tokens + the parts."""
    return "/" + "/".join(p for p in (namespace.strip("/"), *parts) if p)


@dataclass(frozen=True)
class Names:
    world: World
    ros: RosConfig = field(default_factory=RosConfig)

    def namespace(self, body_id: str) -> str:
        return self.ros.namespace_of(body_id)

    def prefix(self, body_id: str) -> str:
        """The frame prefix of a body: '' at the root namespace, else 'ns/'."""
        ns = self.namespace(body_id).strip("/")
        return f"{ns}/" if ns else ""

    def topic(self, body_id: str, *parts: str) -> str:
        return join(self.namespace(body_id), *parts)

    def base_link(self, body_id: str) -> str:
        """Every body's frame: `<prefix>base_link` (buoys too, under their id)."""
        return self.prefix(body_id) + "base_link"

    def odom(self, vessel: str) -> str:
        return self.topic(vessel, "odom")

    def sensor_frame(self, sensor: MountedSensor) -> str:
        return self.prefix(sensor.vessel) + sensor.config.name

    def optical_frame(self, sensor: MountedSensor) -> str:
        """A camera's ROS optical frame (z forward, x right, y down), child of its frame."""
        return self.sensor_frame(sensor) + "_optical"

    def sensor_topic(self, sensor: MountedSensor, suffix: str) -> str:
        return self.topic(sensor.vessel, sensor.config.name, suffix)

    def sensor_topics(self, sensor: MountedSensor) -> list[tuple[str, str]]:
        """(topic, ROS type) of everything a sensor is published as."""
        kind = sensor.config.type
        if kind == "imu":
            suffixes = [("imu", types.IMU)]
        elif kind == "gps":
            suffixes = [("fix", types.NAVSATFIX)]
        elif kind == "lidar":
            suffixes = [("points", types.POINTCLOUD2)]
        elif kind == "radar":
            suffixes = [("points", types.POINTCLOUD2), ("ppi", types.IMAGE)]
        elif kind == "camera":
            suffixes = [(t, types.IMAGE) for t, _ in camera_images(sensor)]
            suffixes.append(("camera_info", types.CAMERA_INFO))
        else:
            suffixes = []
        return [(self.sensor_topic(sensor, s), t) for s, t in suffixes]

    def command_topics(self, vessel: str) -> dict[str, tuple[str, str]]:
        """command -> (topic, ROS type) of the commands a vessel takes from ROS."""
        return {name: (self.topic(vessel, name), kind) for name, kind in COMMANDS.items()}


def camera_images(sensor: MountedSensor) -> list[tuple[str, str]]:
    """(topic suffix, encoding) of a camera's images, for the outputs that are on."""
    on = sensor.params.outputs
    return [pair for name, pairs in CAMERA_OUTPUTS.items() if getattr(on, name) for pair in pairs]
