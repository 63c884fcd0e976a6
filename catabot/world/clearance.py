"""Clearance tests of the traffic planner: footprints against discs, circling tracks, land.

Planning 500 boats with 50 waypoints each lays 25,000 buoys, and every draw of a path is
tested against all of them: tested pairwise that grew as n^2 (minutes of start-up in every
process). `Discs` files each disc in a grid cell, so a test looks at the discs of the cells
around its points only, with exactly the pairwise test's answer.
"""

from __future__ import annotations

import numpy as np

from catabot.world.placement import CLEARANCE_M

Array = np.ndarray
GRID_FROM = 1000  # discs: below, one pairwise array test costs less than finding the cells


class Rows:
    """Rows added one at a time, read as one array. Storage doubles when full: O(1) adds."""

    def __init__(self, width: int) -> None:
        self._data = np.zeros((16, width))
        self._count = 0

    def add(self, *row: float) -> None:
        if self._count == len(self._data):
            self._data = np.concatenate((self._data, np.zeros_like(self._data)))
        self._data[self._count] = row
        self._count += 1

    def __len__(self) -> int:
        return self._count

    @property
    def array(self) -> Array:
        return self._data[: self._count]


class Discs:
    """Discs (x, y, radius) in a grid of `cell_m` cells: a clearance test looks at the 3 x 3
    cells around each point, which hold every disc within reach while the reach (footprint +
    disc + clearance) fits in a cell; beyond that it tests every disc."""

    def __init__(self, cell_m: float = 25.0) -> None:
        self.rows = Rows(3)
        self._cell = cell_m
        self._cells: dict[tuple[int, int], list[int]] = {}
        self._max_r = 0.0

    @property
    def array(self) -> Array:
        return self.rows.array

    def add(self, x: float, y: float, r: float) -> None:
        self._cells.setdefault(self._key(x, y), []).append(len(self.rows))
        self.rows.add(x, y, r)
        self._max_r = max(self._max_r, r)

    def clear_of(self, points: Array, r: float | Array) -> bool:
        """Footprints of radius r at points (K, 2) clear of every disc."""
        if not len(self.rows):
            return True
        if len(self.rows) < GRID_FROM or float(np.max(r)) + self._max_r + CLEARANCE_M > self._cell:
            return clear(points, r, self.array)  # few discs: one array test is faster
        near = self._near(points)
        return not near or clear(points, r, self.array[near])

    def _near(self, points: Array) -> list[int]:
        cells = {tuple(c) for c in np.floor(points / self._cell).astype(int).tolist()}
        keys = {(cx + dx, cy + dy) for cx, cy in cells for dx in (-1, 0, 1) for dy in (-1, 0, 1)}
        return sorted(i for key in keys for i in self._cells.get(key, ()))

    def _key(self, x: float, y: float) -> tuple[int, int]:
        return int(np.floor(x / self._cell)), int(np.floor(y / self._cell))


def clear(points: Array, r: float | Array, discs: Array) -> bool:
    """Footprints of radius r at points (K, 2) clear of discs (M, 3: x, y, radius)."""
    gap = np.hypot(points[:, None, 0] - discs[:, 0], points[:, None, 1] - discs[:, 1])
    return not bool((gap <= np.reshape(r, (-1, 1)) + discs[:, 2] + CLEARANCE_M).any())


def off_rings(points: Array, r: float | Array, rings: Array) -> bool:
    """Footprints at points (K, 2) clear of what boats circling rings (M, 4: centre x, y,
    radius, hull footprint) sweep."""
    d = np.hypot(points[:, None, 0] - rings[:, 0], points[:, None, 1] - rings[:, 1])
    reach = np.reshape(r, (-1, 1)) + rings[:, 3] + CLEARANCE_M
    return not bool((np.abs(d - rings[:, 2]) <= reach).any())


def off_lanes(points: Array, r: float, lanes: Array) -> bool:
    """Footprints of radius r at points (K, 2) clear of lanes (M, 5: segment ends x0, y0,
    x1, y1, and the half-width the vessel using it needs)."""
    a, b = lanes[:, 0:2], lanes[:, 2:4]
    ab = b - a
    rel = points[:, None, :] - a  # (K, M, 2)
    length2 = np.maximum(np.einsum("mi,mi->m", ab, ab), 1e-12)
    t = np.clip(np.einsum("kmi,mi->km", rel, ab) / length2, 0.0, 1.0)
    gap = np.hypot(*(rel - t[:, :, None] * ab).transpose(2, 0, 1))
    return not bool((gap <= r + lanes[:, 4] + CLEARANCE_M).any())


def densify(track: Array, *, loop: bool, step_m: float = 5.0) -> tuple[Array, Array]:
    """Points every `step_m` along a polyline (closed back to its second point if looping),
    each segment a to b at a + t (b - a), t = k (1 / n) for k = 1..n and exactly 1 at its end
    (`np.linspace`'s values, so a plan does not depend on how it is computed), all at once."""
    if loop:
        track = np.vstack([track, track[1:2]])
    a, b = track[:-1], track[1:]
    n = np.maximum((np.hypot(*(b - a).T) / step_m).astype(int), 1)
    seg = np.repeat(np.arange(len(a)), n)
    k = np.arange(len(seg)) - np.repeat(np.cumsum(n) - n, n) + 1  # 1..n within a segment
    t = np.where(k == n[seg], 1.0, k * (1.0 / n[seg]))[:, None]
    pts = np.vstack([track[:1], a[seg] + t * (b[seg] - a[seg])])
    return pts[:, 0], pts[:, 1]
