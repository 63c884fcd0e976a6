"""Reading a thinned /tf back (catabot/run/recorded_poses.py): every body at every tick,
recorded where it was, interpolated between its samples, held after its last."""

from __future__ import annotations

import numpy as np
import pytest

from catabot.ros2.cdr import TfBatch
from catabot.run.recorded_poses import track

FRAMES = ["ego/base_link", "boat_000/base_link"]


def _groups(ticks: int, every: int) -> tuple[list, np.ndarray, np.ndarray]:
    """/tf as the recorder writes it: both bodies at multiples of `every`, the ego alone
    between. The boat moves 1 m a tick along x and turns 0.01 rad a tick."""
    t = np.arange(ticks, dtype=np.float64)
    pos = np.stack([np.stack([t, 0 * t, 0 * t], 1), np.stack([t, 5 + 0 * t, 0 * t], 1)], 1)
    yaw = 0.01 * t
    quat = np.zeros((ticks, 2, 4))
    quat[:, :, 2], quat[:, :, 3] = np.sin(yaw / 2)[:, None], np.cos(yaw / 2)[:, None]
    both, alone = TfBatch("map", FRAMES), TfBatch("map", FRAMES[:1])
    full, part = [], []
    for k in range(ticks):
        if k % every == 0:
            full.append((k, both.encode(k, pos[k], quat[k])))
        else:
            part.append((k, alone.encode(k, pos[k, :1], quat[k, :1])))
    groups = [
        (np.array([k for k, _ in g]), np.array([np.frombuffer(b, np.uint8) for _, b in g]))
        for g in (part, full)
        if g
    ]
    return groups, pos, quat


def test_bodies_between_their_samples_are_interpolated_and_marked() -> None:
    groups, pos, _ = _groups(25, 10)
    got = track(groups, FRAMES, 25)
    assert got.sampled[:, 0].all()
    assert np.flatnonzero(got.sampled[:, 1]).tolist() == [0, 10, 20]
    np.testing.assert_allclose(got.pose[:, 0, :3], pos[:, 0])  # the ego: as recorded
    np.testing.assert_allclose(got.pose[:21, 1, :3], pos[:21, 1], atol=1e-12)  # linear motion
    np.testing.assert_allclose(got.pose[21:, 1, :3], np.repeat(pos[20:21, 1], 4, 0))  # held
    yaw = 2 * np.arctan2(got.pose[:21, 1, 5], got.pose[:21, 1, 6])
    np.testing.assert_allclose(yaw, 0.01 * np.arange(21), atol=1e-5)  # nlerp of a slow turn
    np.testing.assert_allclose(np.linalg.norm(got.pose[:, :, 3:], axis=2), 1.0)


def test_every_tick_recorded_reads_back_as_it_was() -> None:
    groups, pos, quat = _groups(7, 1)
    got = track(groups, FRAMES, 7)
    assert got.sampled.all()
    np.testing.assert_array_equal(got.pose[..., :3], pos)
    np.testing.assert_array_equal(got.pose[..., 3:], quat)


def test_unknown_frames_and_bodies_never_recorded_are_refused() -> None:
    groups, _, _ = _groups(5, 10)
    with pytest.raises(ValueError, match="not this scenario's bodies"):
        track(groups, FRAMES[:1], 5)
    with pytest.raises(ValueError, match="never has"):
        track(groups, [*FRAMES, "buoy_0/base_link"], 5)


def test_a_radar_frame_under_its_vessel_is_not_a_body() -> None:
    """/tf carries base_link -> radar beside the bodies (catabot/ros2/frames.py): skipped."""
    radar = TfBatch(["map", "ego/base_link"], ["ego/base_link", "ego/radar"])
    pos = np.array([[[4.0, 1.0, 0.0], [0.0, 0.0, 3.0]]])
    quat = np.tile([0.0, 0.0, 0.0, 1.0], (1, 2, 1))
    rows = np.frombuffer(radar.encode(0, pos[0], quat[0]), np.uint8)[None]
    got = track([(np.array([0]), rows)], FRAMES[:1], 1)
    np.testing.assert_array_equal(got.pose[0, 0, :3], (4.0, 1.0, 0.0))
