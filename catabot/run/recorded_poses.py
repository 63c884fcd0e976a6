"""Every body's pose at every recorded tick, from a `/tf` whose messages may hold some bodies.

The recorder writes every body's frame at the ticks of `recording.traffic_rate_hz` and the
scenario vessels' alone at the ticks between (services/recorder/thinning.py), so `/tf` has
messages of a few lengths; a radar's frame rides along under its vessel (not a body: skipped,
catabot/ros2/frames.py). Each length is one layout, decoded array-wide; a body's poses
between two of its samples are interpolated (position linearly, orientation by normalised
linear interpolation on the shorter arc), after its last sample held, and `sampled` says
which were recorded.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from catabot.ros2.names import MAP
from catabot.run.cdr_columns import tf_poses

F64 = NDArray[np.float64]


@dataclass(frozen=True)
class Track:
    pose: F64  # (T, N, 7): position xyz, orientation xyzw
    sampled: NDArray[np.bool_]  # (T, N): recorded at that tick (not interpolated)


def track(
    groups: Sequence[tuple[NDArray[np.intp], NDArray[np.uint8]]], frames: Sequence[str], ticks: int
) -> Track:
    """ValueError if a message names a frame not in `frames` or a body is never sampled."""
    pose = np.zeros((ticks, len(frames), 7))
    sampled = np.zeros((ticks, len(frames)), dtype=bool)
    column = {f: j for j, f in enumerate(frames)}
    for index, rows in groups:
        poses = tf_poses(rows)
        bodies = [j for j, parent in enumerate(poses.parents) if parent == MAP]
        if not {poses.frames[j] for j in bodies} <= column.keys():
            raise ValueError("/tf frames are not this scenario's bodies")
        cols = np.array([column[poses.frames[j]] for j in bodies], dtype=np.intp)
        pose[index[:, None], cols] = poses.pose[:, bodies]
        sampled[index[:, None], cols] = True
    if not sampled.any(axis=0).all():
        raise ValueError("/tf never has some of this scenario's bodies")
    for mask in np.unique(sampled, axis=1).T:  # bodies sampled alike, filled together
        if not mask.all():
            same = np.flatnonzero((sampled == mask[:, None]).all(axis=0))
            pose[:, same] = _filled(pose[:, same], np.flatnonzero(mask))
    return Track(pose, sampled)


def _filled(pose: F64, at: NDArray[np.intp]) -> F64:
    """(T, k, 7) poses known at ticks `at` (sorted), every tick filled from its neighbours."""
    t = np.arange(pose.shape[0])
    right = np.clip(np.searchsorted(at, t), 1, max(len(at) - 1, 1)) if len(at) > 1 else None
    if right is None:  # one sample: held
        return np.repeat(pose[at[:1]], pose.shape[0], axis=0)
    lo, hi = at[right - 1], at[right]
    w = np.clip((t - lo) / (hi - lo), 0.0, 1.0)[:, None, None]
    a, b = pose[lo], pose[hi]
    q_b = np.where(np.sum(a[..., 3:] * b[..., 3:], axis=-1, keepdims=True) < 0, -1.0, 1.0)
    out = a + w * (np.concatenate([b[..., :3], q_b * b[..., 3:]], axis=-1) - a)
    out[..., 3:] /= np.linalg.norm(out[..., 3:], axis=-1, keepdims=True)
    return out
