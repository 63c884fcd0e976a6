"""A ray-casting sensor that mostly sees its own vessel is told, once, after its first sample.

Why: a LiDAR mounted 0.2 m up between a catamaran's hulls passed every check (its rays do
not start inside the shape) and returned its own hulls in 13 920 of 16 038 points, a few
decimetres off, every scan. Such a mount is a mistake a user finds only in the recording.
A camera that sees its own bow is normal (the exports leave the bow's boxes out), so only a
view mostly of the carrier is told: SHARE of a LiDAR scan's returns, or of a frame's pixels.
"""

from __future__ import annotations

import logging

import numpy as np

from catabot.bus.messages import CameraFrame, LidarScan, Message
from catabot.run.advice import advise

log = logging.getLogger("sensors.mounts")
SHARE = 0.5


class OwnView:
    """Sensors whose first sample is still to be looked at: key -> (its name, carrier's
    instance id)."""

    def __init__(self, sensors: list[tuple[str, str, int]]) -> None:
        self.pending = {key: (name, instance) for key, name, instance in sensors}

    def check(self, key: str, sample: Message) -> None:
        if key not in self.pending:
            return
        name, own = self.pending.pop(key)
        seen = _instances(sample)
        if seen is None or seen.size == 0:
            return
        share = float(np.count_nonzero(seen == own)) / seen.size
        if share > SHARE:
            what = "returns" if isinstance(sample, LidarScan) else "pixels"
            advise(log, f"{name}: {share:.0%} of its first sample's {what} are its own vessel: "
                        "mount it where it sees over the hull (mount_xyz)")  # fmt: skip


def _instances(sample: Message) -> np.ndarray | None:
    """What each return or pixel hit, by instance id (None: the sensor does not say)."""
    return np.asarray(sample.instance) if isinstance(sample, LidarScan | CameraFrame) else None
