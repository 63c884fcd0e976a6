"""`metrics.json`: navigation figures of every vessel, accumulated tick by tick.

The paper's simulator records navigation metrics beside the data; these are the ones a
planner's test needs first: how far each vessel went, how fast, where it ended, and how
close any two vessels came (the collision margin). Computed from the `BodyStates` batch
with NumPy, so the cost does not grow with a Python loop over vessels; written with
`repr` floats and sorted keys so two runs of one seed give the same bytes.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from catabot.bus.messages import BodyStates


class Metrics:
    def __init__(self, vessel_ids: list[str]) -> None:
        self.ids = vessel_ids  # the first rows of every batch (buoys come after)
        n = len(vessel_ids)
        self.distance = np.zeros(n)
        self.max_speed = np.zeros(n)
        self.last: np.ndarray | None = None
        self.closest = (np.inf, "", "", 0)  # metres, vessel a, vessel b, stamp_ns
        self.stamp_ns = 0

    def add(self, batch: BodyStates) -> None:
        n = len(self.ids)
        pos = np.asarray(batch.position[:n])
        if self.last is not None:
            self.distance += np.linalg.norm(pos - self.last, axis=1)
        self.last = pos.copy()
        speed = np.linalg.norm(np.asarray(batch.linear_velocity[:n]), axis=1)
        self.max_speed = np.maximum(self.max_speed, speed)
        self.stamp_ns = batch.stamp_ns
        self._closest(pos, batch.stamp_ns)

    def _closest(self, pos: np.ndarray, stamp_ns: int) -> None:
        if len(pos) < 2:
            return
        dx = np.subtract.outer(pos[:, 0], pos[:, 0])
        dy = np.subtract.outer(pos[:, 1], pos[:, 1])
        gap2 = np.multiply(dx, dx, out=dx)
        gap2 += np.multiply(dy, dy, out=dy)  # squared: one sqrt, of the minimum only
        np.fill_diagonal(gap2, np.inf)
        i, j = np.unravel_index(int(np.argmin(gap2)), gap2.shape)
        gap = float(np.hypot(pos[i, 0] - pos[j, 0], pos[i, 1] - pos[j, 1]))
        if gap < self.closest[0]:
            a, b = sorted((self.ids[i], self.ids[j]))
            self.closest = (gap, a, b, stamp_ns)

    def write(self, path: Path) -> None:
        vessels = {
            vid: {
                "distance_m": float(self.distance[k]),
                "max_speed_mps": float(self.max_speed[k]),
                "final_position_m": [float(v) for v in self.last[k]]
                if self.last is not None
                else None,
            }
            for k, vid in enumerate(self.ids)
        }
        gap, a, b, when = self.closest
        closest = None if a == "" else {"distance_m": gap, "vessels": [a, b], "stamp_ns": when}
        record = {
            "sim_time_s": self.stamp_ns / 1e9,
            "vessels": vessels,
            "closest_approach": closest,
        }
        path.write_text(json.dumps(record, indent=2, sort_keys=True) + "\n")
