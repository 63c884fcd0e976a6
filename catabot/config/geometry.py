"""Plane geometry for zones: point-in-circle and point-in-polygon, vectorised over points."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

Array = NDArray[np.float64]
Mask = NDArray[np.bool_]


def polygon_area(vertices: Sequence[tuple[float, float]]) -> float:
    """Signed area (shoelace formula): positive for counter-clockwise vertices."""
    p = np.asarray(vertices, dtype=np.float64)
    q = np.roll(p, -1, axis=0)
    return 0.5 * float(np.sum(p[:, 0] * q[:, 1] - q[:, 0] * p[:, 1]))


def polygon_self_intersects(vertices: Sequence[tuple[float, float]]) -> tuple[int, int] | None:
    """The first pair of non-adjacent edges that cross (edge k joins vertex k to k+1), if any.

    Set-up time only (O(E^2)); a crossing polygon would make "inside" depend on the rule used.
    """
    p = np.asarray(vertices, dtype=np.float64)
    n = len(p)
    for a in range(n):
        for b in range(a + 2, n):
            if a == 0 and b == n - 1:
                continue  # adjacent through the closing edge
            if _segments_cross(p[a], p[(a + 1) % n], p[b], p[(b + 1) % n]):
                return a, b
    return None


def _segments_cross(p1: Array, p2: Array, p3: Array, p4: Array) -> bool:
    """Whether closed segments p1p2 and p3p4 share a point (touching counts)."""

    def orient(a: Array, b: Array, c: Array) -> float:
        return float((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]))

    def on(a: Array, b: Array, c: Array) -> bool:
        return bool(min(a[0], b[0]) <= c[0] <= max(a[0], b[0])) and bool(
            min(a[1], b[1]) <= c[1] <= max(a[1], b[1])
        )

    d1, d2 = orient(p3, p4, p1), orient(p3, p4, p2)
    d3, d4 = orient(p1, p2, p3), orient(p1, p2, p4)
    if ((d1 > 0) != (d2 > 0)) and ((d3 > 0) != (d4 > 0)) and 0 not in (d1, d2, d3, d4):
        return True
    return (
        (d1 == 0 and on(p3, p4, p1))
        or (d2 == 0 and on(p3, p4, p2))
        or (d3 == 0 and on(p1, p2, p3))
        or (d4 == 0 and on(p1, p2, p4))
    )


def points_in_circle(x: Array, y: Array, center: tuple[float, float], radius: float) -> Mask:
    """Which points lie in the closed disc."""
    dx, dy = x - center[0], y - center[1]
    return np.asarray(dx * dx + dy * dy <= radius * radius)


class Polygon:
    """A simple polygon, with its edges stored as arrays for a vectorised even-odd test."""

    def __init__(self, vertices: Sequence[tuple[float, float]]) -> None:
        p = np.asarray(vertices, dtype=np.float64)
        q = np.roll(p, -1, axis=0)
        self.x0, self.y0 = p[:, 0], p[:, 1]
        dy = q[:, 1] - p[:, 1]
        # Horizontal edges never straddle a ray; a dummy slope keeps the division finite.
        self.slope = (q[:, 0] - p[:, 0]) / np.where(dy == 0.0, 1.0, dy)
        self.y1 = q[:, 1]

    def contains(self, x: Array, y: Array) -> Mask:
        """Even-odd rule: a horizontal ray from each point crosses the boundary an odd number
        of times when the point is inside. Points are (N,), edges (E,): one (N, E) pass."""
        xs, ys = np.asarray(x, dtype=np.float64), np.asarray(y, dtype=np.float64)
        px, py = xs[..., None], ys[..., None]
        straddles = (self.y0 > py) != (self.y1 > py)
        x_cross = self.x0 + (py - self.y0) * self.slope
        crossings = np.count_nonzero(straddles & (px < x_cross), axis=-1)
        return np.asarray(crossings % 2 == 1)
