"""Whole channels of ROS 2 `nav_msgs/Odometry` and `tf2_msgs/TFMessage` decoded at once.

A channel's messages carry the same frame names every tick, so they have one length and
their floats sit at the same offsets in every message: the layout is read once from the
first message (a small CDR walk) and every message's floats are then gathered with NumPy
from the (messages, length) byte array `McapIndex.rows` gives, instead of a decoder call per
message (mcap_ros2 spends ≈2 ms on a 376-body TFMessage). The bytes that hold the frame
names are compared across all messages, so a message whose layout differs is refused, never
misread.
"""

from __future__ import annotations

import struct
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from catabot.errors import CataBotError

F64 = NDArray[np.float64]
_POSE = 7  # x y z, qx qy qz qw
_ENCAPSULATION = 4  # CDR little-endian header; alignment counts from its end


class CdrLayoutError(CataBotError, ValueError):
    """Messages of one channel that do not share one layout."""


class _Walk:
    """Offsets in one CDR message; every `string` records the bytes that hold it."""

    def __init__(self, data: bytes) -> None:
        self.data, self.pos = data, _ENCAPSULATION
        self.fixed: list[tuple[int, int]] = []  # byte ranges every message must share

    def align(self, n: int) -> None:
        self.pos += -(self.pos - _ENCAPSULATION) % n

    def u32(self) -> int:
        self.align(4)
        (value,) = struct.unpack_from("<I", self.data, self.pos)
        self.pos += 4
        return int(value)

    def string(self) -> str:
        start = self.pos
        n = self.u32()
        text = self.data[self.pos : self.pos + n].rstrip(b"\0").decode()
        self.pos += n
        self.fixed.append((start, self.pos))
        return text

    def floats(self, count: int) -> int:
        """Skip `count` float64s; their offset."""
        self.align(8)
        start = self.pos
        self.pos += 8 * count
        return start

    def stamp(self) -> None:
        self.align(4)
        self.pos += 8


@dataclass(frozen=True)
class Poses:
    """Per message: `frames` (N,) child frames, `parents` (N,) theirs, `pose` (T, N, 7) x y
    z qx qy qz qw."""

    frames: tuple[str, ...]
    parents: tuple[str, ...]
    pose: F64


@dataclass(frozen=True)
class Odometry:
    """Per message: pose (T, 7) in the parent frame, twist (T, 6) linear + angular (body)."""

    child_frame: str
    pose: F64
    twist: F64


def _gather(rows: NDArray[np.uint8], offsets: list[int], count: int) -> F64:
    """Float64 runs of `count` at `offsets` in every row: (T, len(offsets), count)."""
    idx = np.asarray(offsets, dtype=np.intp)[:, None] + np.arange(8 * count)
    block = np.ascontiguousarray(rows[:, idx])
    return block.view("<f8").reshape(len(rows), len(offsets), count)


def _check_fixed(rows: NDArray[np.uint8], walk: _Walk, what: str) -> None:
    if walk.pos > rows.shape[1]:
        raise CdrLayoutError(f"{what}: messages are shorter than their own layout")
    idx = np.concatenate([np.arange(a, b) for a, b in walk.fixed] or [np.empty(0, np.intp)])
    if len(idx) and (rows[:, idx] != rows[:1, idx]).any():
        raise CdrLayoutError(f"{what}: frame names differ between messages of one length")


def tf_poses(rows: NDArray[np.uint8], what: str = "/tf") -> Poses:
    """Every transform of every TFMessage in `rows` (one row per message, one length)."""
    walk = _Walk(bytes(rows[0]))
    count_at = walk.pos
    count = walk.u32()
    walk.fixed.append((count_at, walk.pos))
    frames, parents, offsets = [], [], []
    for _ in range(count):
        walk.stamp()
        parents.append(walk.string())
        frames.append(walk.string())
        offsets.append(walk.floats(_POSE))
    _check_fixed(rows, walk, what)
    pose = _gather(rows, offsets, _POSE) if offsets else np.empty((len(rows), 0, _POSE))
    return Poses(tuple(frames), tuple(parents), pose)


def odometry(rows: NDArray[np.uint8], what: str = "odometry") -> Odometry:
    """Pose and twist of every Odometry message in `rows` (covariances skipped)."""
    walk = _Walk(bytes(rows[0]))
    walk.stamp()
    walk.string()  # the parent frame
    child = walk.string()
    pose_at = walk.floats(_POSE)
    walk.floats(36)  # pose covariance
    twist_at = walk.floats(6)
    walk.floats(36)  # twist covariance
    _check_fixed(rows, walk, what)
    return Odometry(
        child, _gather(rows, [pose_at], _POSE)[:, 0], _gather(rows, [twist_at], 6)[:, 0]
    )
