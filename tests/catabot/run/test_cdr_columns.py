"""Whole Odometry and TFMessage channels decoded at fixed offsets give the values rosbags'
serializer (an implementation no one here wrote) put in, for frame names of every length."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest
from rosbags.typesys import Stores, get_typestore

from catabot.run import cdr_columns

TS = get_typestore(Stores.ROS2_JAZZY)
T = TS.types
NAMES = ["a", "ab", "abc", "ego", "ego1", "boat_007", "ümlaut", "x" * 33]


def _header(k: int, frame: str) -> Any:
    return T["std_msgs/msg/Header"](stamp=T["builtin_interfaces/msg/Time"](sec=k, nanosec=7 * k),
                                    frame_id=frame)  # fmt: skip


def _odometry(k: int, child: str, pose: np.ndarray, twist: np.ndarray) -> bytes:
    v3, q = T["geometry_msgs/msg/Vector3"], T["geometry_msgs/msg/Quaternion"]
    p = T["geometry_msgs/msg/Pose"](position=T["geometry_msgs/msg/Point"](*pose[:3]),
                                    orientation=q(*pose[3:]))  # fmt: skip
    msg = T["nav_msgs/msg/Odometry"](
        header=_header(k, "map"),
        child_frame_id=child,
        pose=T["geometry_msgs/msg/PoseWithCovariance"](pose=p, covariance=np.arange(36.0)),
        twist=T["geometry_msgs/msg/TwistWithCovariance"](
            twist=T["geometry_msgs/msg/Twist"](linear=v3(*twist[:3]), angular=v3(*twist[3:])),
            covariance=-np.arange(36.0),
        ),
    )
    return bytes(TS.serialize_cdr(msg, "nav_msgs/msg/Odometry"))


def _tf(k: int, frames: list[str], pose: np.ndarray) -> bytes:
    v3, q = T["geometry_msgs/msg/Vector3"], T["geometry_msgs/msg/Quaternion"]
    transforms = [
        T["geometry_msgs/msg/TransformStamped"](
            header=_header(k, "map"), child_frame_id=f,
            transform=T["geometry_msgs/msg/Transform"](translation=v3(*p[:3]), rotation=q(*p[3:])),
        )
        for f, p in zip(frames, pose, strict=True)
    ]  # fmt: skip
    return bytes(TS.serialize_cdr(T["tf2_msgs/msg/TFMessage"](transforms=transforms),
                                  "tf2_msgs/msg/TFMessage"))  # fmt: skip


def _rows(payloads: list[bytes]) -> np.ndarray:
    return np.frombuffer(b"".join(payloads), np.uint8).reshape(len(payloads), -1)


@pytest.mark.parametrize("child", NAMES)
def test_odometry_pose_and_twist(child: str) -> None:
    rng = np.random.default_rng(len(child))
    pose, twist = rng.normal(size=(5, 7)), rng.normal(size=(5, 6))
    got = cdr_columns.odometry(_rows([_odometry(k, child, pose[k], twist[k]) for k in range(5)]))
    assert got.child_frame == child
    assert (got.pose == pose).all() and (got.twist == twist).all()


def test_tf_poses_of_every_frame() -> None:
    pose = np.random.default_rng(1).normal(size=(4, len(NAMES), 7))
    got = cdr_columns.tf_poses(_rows([_tf(k, NAMES, pose[k]) for k in range(4)]))
    assert got.frames == tuple(NAMES) and (got.pose == pose).all()


def test_messages_of_one_length_with_other_names_are_refused() -> None:
    pose = np.zeros((2, 2, 7))
    rows = _rows([_tf(0, ["ab", "cd"], pose[0]), _tf(1, ["ab", "ce"], pose[1])])
    with pytest.raises(cdr_columns.CdrLayoutError, match="frame names differ"):
        cdr_columns.tf_poses(rows)
