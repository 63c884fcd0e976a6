"""Moving obstacles for navigate.py: the occupancy grid's cells grouped into objects, each
object followed from scan to scan, its velocity estimated. Pure NumPy, tested in
tests/examples/test_tracking.py.

A scan says where things are, not how they move; a boat crossing at 1 m/s looks like a rock
to a planner that sees one scan. So cells are grouped into 8-connected clusters, each
cluster's centroid (in `map`, from the GPS fix) is matched to the nearest predicted track
(mutual nearest, within a gate) and an alpha-beta filter smooths its position and velocity
(a centroid jumps as a hull turns and shows another side; the filter takes a fraction).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from planning import GridSpec, cell_centres, cell_grid, occupancy

F64 = NDArray[np.float64]
I64 = NDArray[np.int64]


def clusters(grid: NDArray[np.bool_], reach: int = 2) -> I64:
    """Labels (same shape): 0 for free cells, 1..n for the cluster of each occupied one,
    cells up to `reach` cells apart (in x and y) being one object: a hull far away shows as
    beams a cell or two apart. Works on the occupied cells alone: each takes the largest
    label among itself and its neighbours, then its label's label (pointer jumping), until
    nothing changes."""
    rows, cols = np.nonzero(grid)
    m = len(rows)
    r, steps = reach, range(-reach, reach + 1)
    index = np.full((grid.shape[0] + 2 * r, grid.shape[1] + 2 * r), -1)
    index[rows + r, cols + r] = np.arange(m)
    near = np.stack([index[rows + r + dy, cols + r + dx] for dy in steps for dx in steps], axis=1)
    near = np.where(near >= 0, near, np.arange(m)[:, None])  # no neighbour: itself
    label = np.arange(m)
    while True:
        grown = label[near].max(axis=1)
        grown = grown[grown]
        if np.array_equal(grown, label):
            break
        label = grown
    out = np.zeros(grid.shape, np.int64)
    out[rows, cols] = np.unique(label, return_inverse=True)[1].ravel() + 1
    return out


def centroids(labels: I64, cells: F64) -> F64:
    """(n, 2) mean position of each cluster's cells; `cells` (rows, cols, 2) the position of
    every cell."""
    rows, cols = np.nonzero(labels)
    own, at = labels[rows, cols] - 1, cells[rows, cols]
    n = int(labels.max())
    counts = np.maximum(np.bincount(own, minlength=n), 1)
    sums = np.stack([np.bincount(own, at[:, i], minlength=n) for i in (0, 1)], axis=1)
    return sums / counts[:, None]


@dataclass(frozen=True)
class Tracks:
    """Followed objects in `map`: filtered position, velocity, and scans seen in a row."""

    position: F64
    velocity: F64
    seen: I64

    @classmethod
    def none(cls) -> Tracks:
        return cls(np.empty((0, 2)), np.empty((0, 2)), np.empty(0, np.int64))


@dataclass(frozen=True)
class Tracker:
    gate_m: float = 2.0  # farther from every prediction: a new object
    alpha: float = 0.5  # share of the position residual taken
    beta: float = 0.08  # share of the residual / dt taken into the velocity
    max_speed_mps: float = 4.0  # a faster estimate is a mismatch, clamped

    def update(self, tracks: Tracks, found: F64, dt: float) -> Tracks:
        """The tracks after a scan whose clusters have centroids `found` (m, 2): track i is
        centroid i's object. Unmatched tracks are dropped (a 360 degree scan comes every
        period: an object it lost is gone or hidden), unmatched centroids start still."""
        predicted = tracks.position + tracks.velocity * dt
        m = len(found)
        match = np.full(m, -1)
        if m and len(predicted):
            d = np.hypot(*(found[:, None, :] - predicted[None, :, :]).transpose(2, 0, 1))
            nearest, back = d.argmin(axis=1), d.argmin(axis=0)
            mutual = (back[nearest] == np.arange(m)) & (d[np.arange(m), nearest] < self.gate_m)
            match = np.where(mutual, nearest, -1)
        old = match >= 0
        residual = np.zeros((m, 2))
        residual[old] = found[old] - predicted[match[old]]
        position, velocity = found.copy(), np.zeros((m, 2))
        position[old] = predicted[match[old]] + self.alpha * residual[old]
        velocity[old] = tracks.velocity[match[old]] + self.beta * residual[old] / dt
        speed = np.hypot(velocity[:, 0], velocity[:, 1])
        velocity *= np.minimum(1.0, self.max_speed_mps / np.maximum(speed, 1e-9))[:, None]
        seen = np.ones(m, np.int64)
        seen[old] = tracks.seen[match[old]] + 1
        return Tracks(position, velocity, seen)


def cell_velocities(labels: I64, tracks: Tracks, min_seen: int) -> F64:
    """(M, 2) the velocity of every occupied cell (in `np.nonzero` order, as
    planning.cell_centres), its object's; nil for an object seen fewer than `min_seen` scans
    in a row (its velocity is not known yet)."""
    own = labels[np.nonzero(labels)] - 1
    known = tracks.seen[own] >= min_seen
    return np.where(known[:, None], tracks.velocity[own], 0.0)


class Obstacles:
    """The per-scan pipeline with its memory: grid, clusters, tracks, moving cells."""

    def __init__(self, spec: GridSpec, tracker: Tracker, min_seen: int = 3) -> None:
        self.spec, self.tracker, self.min_seen = spec, tracker, min_seen
        self.cells = cell_grid(spec)
        self.tracks = Tracks.none()

    def update(self, offsets: F64, reflectivities: F64, position: F64, dt: float
               ) -> tuple[F64, F64]:  # fmt: skip
        """Occupied cells (M, 2, offsets from the vessel) and their velocities (M, 2) after
        a scan (ENU offsets of its returns and their reflectivities) taken at `position`
        (`map`)."""
        labels = clusters(occupancy(offsets, reflectivities, self.spec))
        found = centroids(labels, self.cells) + np.asarray(position)
        self.tracks = self.tracker.update(self.tracks, found, dt)
        return cell_centres(labels > 0, self.spec), cell_velocities(
            labels, self.tracks, self.min_seen
        )
