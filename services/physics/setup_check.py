"""The checks a PhysicsWorld's set-up must pass before DART is touched."""

from __future__ import annotations

import math
from collections.abc import Sequence

from catabot.config.vessel import VesselModel

StartPose = tuple[float, float, float, float]  # x, y, z (m, map ENU), yaw (rad)


def check_setup(
    vessels: Sequence[tuple[str, VesselModel, StartPose]],
    dt_s: float,
    water_density: float,
    gravity: float,
) -> None:
    """Reject a set-up that would give a meaningless or non-deterministic world."""
    if not vessels:
        raise ValueError("PhysicsWorld needs at least one vessel")
    if not (math.isfinite(dt_s) and dt_s > 0):
        raise ValueError(f"dt_s must be a finite number > 0 (got {dt_s})")
    if not (math.isfinite(water_density) and water_density > 0):
        raise ValueError(f"water_density must be a finite number > 0 (got {water_density})")
    if not (math.isfinite(gravity) and gravity >= 0):
        raise ValueError(f"gravity must be a finite number >= 0 (got {gravity})")
    seen: set[str] = set()
    for vid, _, pose in vessels:
        if not vid or vid in seen:
            raise ValueError(f"vessel ids must be unique and non-empty (got {vid!r} twice)")
        seen.add(vid)
        if len(pose) != 4 or not all(math.isfinite(v) for v in pose):
            raise ValueError(f"vessel {vid!r}: start pose must be 4 finite numbers (x, y, z, yaw)")
