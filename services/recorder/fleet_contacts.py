"""Collisions among the traffic: boats and buoys touching each other, not a scenario vessel.

Why: `metrics.Metrics` measures the scenario's vessels against everything, so boats of the
traffic could ram each other unreported (33 pairs a minute in Table II's 100-boat cell,
found only by counting DART's contacts by hand). A user judging a scene, or a dataset of it,
needs that figure. Checked on the ticks whose traffic states are recorded
(`recording.traffic_rate_hz`): the same plan-view hull boxes as the vessels' collisions,
found by a sweep along x (pairs of bodies within reach, never all pairs), so it costs a
few tens of microseconds a recorded tick with 100 boats. An episode is a pair touching from
its first sample until it has been apart for the episode gap, as for the vessels.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from catabot.bus.messages import BodyStates
from catabot.world.hulls import CONTACT_M, boxes_touch
from services.recorder.episodes import Episode

Array = NDArray[np.float64]
Rows = NDArray[np.intp]


class FleetContacts:
    def __init__(
        self, offset: Array, half: Array, reach: Array, *, first: int, period: int, gap_ns: int
    ) -> None:
        """Bodies from row `first` on (the traffic and the buoys), their plan-view boxes
        (centre offset, half extents) and the radius holding each; a check every `period`
        ticks."""
        self.first, self.period, self.gap_ns = first, period, gap_ns
        self.offset, self.half, self.reach = offset[first:], half[first:], reach[first:]
        self.open: dict[tuple[int, int], tuple[int, int]] = {}  # pair: (start, last seen)
        self.done: list[Episode] = []

    def add(self, batch: BodyStates) -> None:
        if batch.tick % self.period or len(self.reach) < 2:
            return
        a, b = self.touching(batch.position[self.first :, :2], batch.orientation[self.first :])
        stamp = batch.stamp_ns
        for pair in zip((a + self.first).tolist(), (b + self.first).tolist(), strict=True):
            start, _ = self.open.get(pair, (stamp, stamp))
            self.open[pair] = (start, stamp)
        for pair, (start, seen) in list(self.open.items()):
            if stamp - seen > self.gap_ns:
                self.done.append(Episode(pair, start, seen, float("inf"), 0))
                del self.open[pair]

    def touching(self, xy: Array, quat: Array) -> tuple[Rows, Rows]:
        """The pairs (a < b, rows from `first`) whose boxes are within CONTACT_M."""
        a, b = _near_pairs(xy, self.reach)
        if a.size == 0:
            return a, b
        hit = boxes_touch(xy, quat, (self.offset, self.half), a, b)
        return a[hit], b[hit]

    def all(self) -> list[Episode]:
        """Every episode, ended or not, by start time then pair (deterministic)."""
        going = [
            Episode(pair, start, None, float("inf"), 0) for pair, (start, _) in self.open.items()
        ]
        return sorted([*self.done, *going], key=lambda e: (e.start_ns, e.slot))


def _near_pairs(xy: Array, reach: Array) -> tuple[Rows, Rows]:
    """Pairs (a < b) whose bounding circles (radius `reach`) are within CONTACT_M: a sweep
    along x, each body against those after it within the widest reach."""
    order = np.argsort(xy[:, 0], kind="stable")
    xs = xy[order, 0]
    end = np.searchsorted(xs, xs + 2.0 * reach.max() + CONTACT_M, side="right")
    count = end - np.arange(len(xs)) - 1
    i = np.repeat(np.arange(len(xs)), count)
    j = i + 1 + np.arange(len(i)) - np.repeat(np.cumsum(count) - count, count)
    a, b = np.minimum(order[i], order[j]), np.maximum(order[i], order[j])
    gap = np.hypot(*(xy[a] - xy[b]).T)
    near = gap <= reach[a] + reach[b] + CONTACT_M
    return a[near], b[near]
