"""Bus messages of one world as ROS 2 messages: the one conversion the recorder (`run.mcap`)
and the gateway (services/ros) share, so a recording and a live run have the same topics,
types, frames and bytes.

- `world/states` (BodyStates) -> each vessel's `odom` (nav_msgs/Odometry in `map`, child
  `<ns>/base_link`, body-frame velocities, zero covariance: the state is exact) and one
  `/tf` TFMessage of every body (map -> `<ns>/base_link`, buoys included) and every radar
  (base_link -> its level frame: frames.py);
- the sensors' samples -> convert_sensors.py; `/tf_static`: base_link -> every other sensor
  frame;
- twist and thrust commands -> `cmd_vel` (geometry_msgs/Twist: linear.x surge, angular.z
  yaw rate) and `thrust` (std_msgs/Float64MultiArray, one value per thruster, -1..1);
- the buoys -> `/buoys` (visualization_msgs/MarkerArray): one box per buoy, in the buoy's own
  frame and `frame_locked`, so it is sent once and follows `/tf`.
"""

from __future__ import annotations

import typing

import numpy as np

from catabot.bus.messages import BodyStates, Message, ThrustCmd, TwistBatch, TwistCmd, check_ids
from catabot.config.ros import RosConfig
from catabot.ros2 import types
from catabot.ros2.cdr import OdometryBatch
from catabot.ros2.cdr_more import clock, twist, twist_rows
from catabot.ros2.convert_sensors import Convert, Out, Want, converter, everything
from catabot.ros2.frames import BodyFrames, static_transforms, tf_message
from catabot.ros2.names import BUOYS, CLOCK, MAP, TF_STATIC, Names
from catabot.world.world import World


class Converter:
    """Every ROS 2 message of one world. `boats=False` leaves the traffic boats' odometry out
    (the gateway's `ros.traffic`); their frames stay on `/tf`."""

    def __init__(self, world: World, ros: RosConfig | None = None, *, boats: bool = True) -> None:
        self.world = world
        self.names = names = Names(world, ros or RosConfig())
        odom = [b for b in world.vessels if boats or b.kind == "vessel"]
        self.odom_rows = np.array([b.row for b in odom], dtype=np.intp)
        self.odom_topics = tuple(names.odom(b.id) for b in odom)
        self._odometry = OdometryBatch(MAP, [names.base_link(b.id) for b in odom])
        self._tf = BodyFrames(names, world.bodies)
        self.boat_twist_topics = tuple(names.topic(b, "cmd_vel") for b in world.boat_ids)
        self._sensors: dict[str, Convert] = {
            world.keys.relative(s.key): converter(names, s) for s in world.sensors
        }

    def odometry_groups(self, batch: BodyStates) -> list[tuple[np.ndarray, np.ndarray]]:
        """The Odometry payloads as (indices into `odom_topics`, (k, L) byte matrix) groups,
        one per payload length (OdometryBatch). Raises ValueError for other bodies."""
        check_ids("world/states", batch.tick, batch.ids, self.world.body_ids)
        values = np.concatenate(batch.arrays()[:4], axis=1)[self.odom_rows]
        return self._odometry.encode_groups(batch.stamp_ns, values)

    def odometry(self, batch: BodyStates) -> list[bytes]:
        """One Odometry payload per `odom_topics` entry."""
        out: list[bytes] = [b""] * len(self.odom_topics)
        for rows, block in self.odometry_groups(batch):
            data, length = block.tobytes(), block.shape[1]
            for j, i in enumerate(rows.tolist()):
                out[i] = data[j * length : (j + 1) * length]
        return out

    def tf(self, batch: BodyStates) -> bytes:
        """Every body's frame in `map` and every radar's on its vessel, one TFMessage (rows
        checked by `odometry_groups`)."""
        return self._tf.encode(batch)

    def static_tf(self) -> Out | None:
        """base_link -> every sensor frame, stamped 0 (static); None without sensors."""
        transforms = static_transforms(self.names)
        return Out(TF_STATIC, types.TF, tf_message(transforms, 0)) if transforms else None

    def clock(self, stamp_ns: int) -> Out:
        return Out(CLOCK, types.CLOCK, clock(stamp_ns))

    def sensor(self, stream: str, msg: Message, want: Want = everything) -> list[Out]:
        """A sensor sample from `sensor/<vessel>/<sensor>` as the topics `want` asks for;
        ValueError if the stream is unknown or the sample mistyped."""
        convert = self._sensors.get(stream)
        if convert is None:
            raise ValueError(f"{stream}: no sensor of this world publishes there")
        return convert(msg, want)

    def is_sensor(self, stream: str) -> bool:
        return stream in self._sensors

    def command(self, vessel: str, msg: Message) -> Out:
        """A twist or thrust command given to `vessel` (recorded as the gateway takes it)."""
        if isinstance(msg, TwistCmd):
            data = twist(msg.surge, msg.yaw_rate)
            return Out(self.names.topic(vessel, "cmd_vel"), types.TWIST, data)
        if isinstance(msg, ThrustCmd):
            return Out(self.names.topic(vessel, "thrust"), types.FLOAT64_ARRAY, thrust(msg.thrust))
        raise ValueError(f"{vessel}: no ROS 2 form for a {type(msg).__name__} command")

    def boat_twists(self, batch: TwistBatch, boats: tuple[str, ...] | None = None) -> np.ndarray:
        """The set-points of `boats` (every traffic boat, or a traffic shard's block) as
        Twists, an (N, 52) byte matrix in their order. Raises ValueError for other boats or
        shapes."""
        batch.check(self.world.boat_ids if boats is None else boats)
        return twist_rows(batch.surge, batch.yaw_rate)

    def buoys(self) -> Out | None:
        """One box marker per buoy, in its own frame (sent once); None without buoys."""
        if not self.world.buoys:
            return None
        markers = [_marker(self.names.base_link(b.id), b.row, *b.model.hull_box())
                   for b in self.world.buoys]  # fmt: skip
        data = types.serialize(types.new(types.MARKER_ARRAY, markers=markers), types.MARKER_ARRAY)
        return Out(BUOYS, types.MARKER_ARRAY, data)


def thrust(values: typing.Sequence[float]) -> bytes:
    """std_msgs/Float64MultiArray of one value per thruster (no layout dimensions)."""
    layout = types.new("std_msgs/msg/MultiArrayLayout", dim=[], data_offset=0)
    msg = types.new(types.FLOAT64_ARRAY, layout=layout, data=np.asarray(values, np.float64))
    return types.serialize(msg, types.FLOAT64_ARRAY)


ORANGE = {"r": 1.0, "g": 0.45, "b": 0.0, "a": 1.0}


def _marker(frame: str, row: int, lo: np.ndarray, hi: np.ndarray) -> typing.Any:
    """A CUBE marker: the body's hull box (what physics collides and the sensors see)."""
    centre, size = (lo + hi) / 2, hi - lo
    v = "geometry_msgs/msg/Vector3"
    return types.new(
        "visualization_msgs/msg/Marker",
        header=types.header(0, frame), ns="buoys", id=row, type=1, action=0,
        pose=types.new("geometry_msgs/msg/Pose",
                       position=types.new("geometry_msgs/msg/Point", **_xyz(centre)),
                       orientation=types.new("geometry_msgs/msg/Quaternion", x=0.0, y=0.0,
                                             z=0.0, w=1.0)),
        scale=types.new(v, **_xyz(size)), color=types.new("std_msgs/msg/ColorRGBA", **ORANGE),
        lifetime=types.new("builtin_interfaces/msg/Duration", sec=0, nanosec=0),
        frame_locked=True, points=[], colors=[], texture_resource="",
        texture=types.new("sensor_msgs/msg/CompressedImage", header=types.header(0, ""),
                          format="", data=np.zeros(0, np.uint8)),
        uv_coordinates=[], text="", mesh_resource="",
        mesh_file=types.new("visualization_msgs/msg/MeshFile", filename="",
                            data=np.zeros(0, np.uint8)),
        mesh_use_embedded_materials=False,
    )  # fmt: skip


def _xyz(v: np.ndarray) -> dict[str, float]:
    x, y, z = (float(c) for c in v)
    return {"x": x, "y": y, "z": z}
