"""Traffic boats keep clear: marks rounded at a passing distance, the water ahead kept free.

Why: boats steered straight at the buoys on their waypoints and across the other boats'
buoys and tracks. In Table II's waypoint row (100 boats, 275 buoys) 19 buoys were rammed in
a minute, some dragged 15 m, and circling boats pushed each other round their circles.
Real traffic keeps clear (COLREGs rules 8 and 14: alter course early; head-on, both to
starboard), and a buoy knocked about keeps physics busy for a minute (sleep.py).

Two rules, vectorised over boats x obstacles (buoys and traffic boats by default; the
scenario's vessels only with `traffic.avoid.vessels`), each a footprint circle:
- Rounding: a waypoint with a buoy on it (a mark) is aimed at `pass_m` to the right of the
  line of sight, so the boat leaves the mark to port about that far off; it counts as
  reached within the tolerance plus `pass_m` of the mark.
- Corridor: a buoy ahead of a boat on the arc it is turning on, within lookahead_s at its
  speed and closer to that track than both footprints plus the clearance, turns it at its
  full rate away from the side the buoy bears on now: to starboard unless it lies well to
  starboard (a third of the corridor). The nearest one decides; first, anything closer than
  that anywhere but astern (a boat turning at low speed, two boats alongside), buoy or
  boat, which it simply turns away from, backing off while it lies under the bow. The
  boat's own law resumes when the corridor is clear. The marks on a boat's own path are
  left to the first rule. Boats under way ahead are not corridor obstacles: reacting to
  where another boat is now, both boats of a pair turned, each to the side the other bore
  on, and still met; colregs.py gives such meetings to one of the two.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

Array = NDArray[np.float64]
Rows = NDArray[np.intp]
MARK_M = 0.5  # a waypoint this close to a buoy's anchor is that buoy's mark
PAIRS = 250_000  # boats x obstacles compared at once (bounds the temporaries)


@dataclass(frozen=True)
class KeepClear:
    """How each boat keeps clear, fixed for a run (the traffic service builds it)."""

    anchors: Array  # (B, 2) the buoys' anchors: waypoints on them are marks
    pass_m: Array  # (N,) how far off a boat rounds a mark (0: it steers at the point)
    width: Array  # (N,) its footprint plus the clearance
    lookahead_s: float


@dataclass(frozen=True)
class Obstacles:
    """What boats keep clear of at one guidance tick: footprint circles in `map`."""

    xy: Array  # (M, 2)
    radius: Array  # (M,)
    own: Rows  # (N,): each boat's own row among them, -1 when it is not one
    velocity: Array  # (M, 2) over ground, map frame
    turn_rate: Array  # (M,) rad/s, to port positive
    under_way: NDArray[np.bool_]  # (M,): boats and vessels, whose meetings colregs.py rules

    @classmethod
    def fixed(cls, xy: Array, radius: Array, own: Rows) -> Obstacles:
        """Obstacles that do not move and are not boats (buoys, marks)."""
        still = np.zeros(len(xy))
        return cls(xy, radius, own, np.zeros_like(xy), still, np.zeros(len(xy), dtype=bool))


def marks_on(path: Array, anchors: Array) -> NDArray[np.bool_]:
    """Which points of a path (K, 2) carry a buoy (anchors (B, 2))."""
    if len(anchors) == 0 or len(path) == 0:
        return np.zeros(len(path), dtype=bool)
    gap = np.hypot(*np.subtract(path[:, None, :], anchors[None, :, :]).transpose(2, 0, 1))
    return np.asarray(gap.min(axis=1) < MARK_M)


def mark_aim(pos: Array, mark: Array, pass_m: Array) -> Array:
    """The point `pass_m` to the right of each boat's line of sight to its mark."""
    los = mark - pos
    dist = np.maximum(np.hypot(los[:, 0], los[:, 1]), 1e-9)
    right = np.column_stack((los[:, 1], -los[:, 0])) / dist[:, None]
    return np.asarray(mark + pass_m[:, None] * right)


def corridor_turn(
    pos: Array, chi: Array, curvature: Array, reach: Array, width: Array, obstacles: Obstacles,
    marks: Array,
) -> tuple[Array, NDArray[np.bool_]]:  # fmt: skip
    """Per boat: -1 turn to starboard, +1 to port, 0 its corridor is clear; and whether it
    must back off, an obstacle being under its bow. The corridor follows the arc the boat is
    turning on (curvature (N,), 1/m, left positive), `reach` (N,) metres along it, `width`
    (N,) its footprint plus the clearance either side; marks (N, K, 2): the marks on a
    boat's own path (nan: none), which it rounds instead."""
    out, stop = np.zeros(len(pos)), np.zeros(len(pos), dtype=bool)
    step = max(1, PAIRS // max(len(obstacles.xy), 1))
    for s in range(0, len(pos), step):
        rows = np.arange(s, min(s + step, len(pos)))
        boat, obs = near_pairs(pos, reach + width + obstacles.radius.max(), obstacles, rows)
        boat, obs = _others(boat, obs, (pos, width), obstacles, marks)
        threat = _threats(boat, obs, (pos, chi, curvature, reach, width), obstacles)
        boat, along, left, wide, bow = threat
        order = np.lexsort((along, boat))  # each boat's nearest threat first
        first = order[np.unique(boat[order], return_index=True)[1]]
        bias = np.where(along[first] > 0.0, wide[first] / 3.0, 0.0)  # far: starboard first
        out[boat[first]] = np.where(left[first] < -bias, 1.0, -1.0)  # the side it bears now
        stop[boat[first]] = bow[first]
    return out, stop


def _others(
    boat: Rows, obs: Rows, boats: tuple[Array, Array], obstacles: Obstacles, marks: Array
) -> tuple[Rows, Rows]:
    """The pairs without a boat itself, the marks on its own path and the boats under way
    that are not close (those are colregs.py's; `_threats` meets a close one here)."""
    pos, width = boats
    rel = obstacles.xy[obs] - pos[boat]
    near = rel[:, 0] ** 2 + rel[:, 1] ** 2 < (width[boat] + obstacles.radius[obs]) ** 2
    keep = (obs != obstacles.own[boat]) & (near | ~obstacles.under_way[obs])
    boat, obs = boat[keep], obs[keep]
    gap = obstacles.xy[obs][:, None, :] - marks[boat]  # (pairs, K, 2); nan: no mark
    mark = np.any(gap[..., 0] ** 2 + gap[..., 1] ** 2 < MARK_M**2, axis=1)
    return boat[~mark], obs[~mark]


def _threats(
    boat: Rows, obs: Rows, boats: tuple[Array, ...], obstacles: Obstacles
) -> tuple[Rows, Array, Array, Array, NDArray[np.bool_]]:
    """The pairs where the obstacle is in the boat's corridor or close (distance 0 along
    it), with where it lies ahead and to the left, the corridor's half-width and whether
    it is under the bow."""
    pos, chi, curvature, reach, width = boats
    rel = obstacles.xy[obs] - pos[boat]
    cos, sin = np.cos(chi[boat]), np.sin(chi[boat])
    ahead, left = rel[:, 0] * cos + rel[:, 1] * sin, rel[:, 1] * cos - rel[:, 0] * sin
    along, off = _on_arc(ahead, left, curvature[boat])
    wide = width[boat] + obstacles.radius[obs]
    hit = (along > 0.0) & (along < reach[boat] + wide) & (np.abs(off) < wide)
    hit &= ~obstacles.under_way[obs]  # boats meeting boats: colregs.py
    close = (ahead > -width[boat]) & (np.hypot(ahead, left) < wide)  # alongside too
    bow = close & (ahead > 0.0) & (np.abs(left) < width[boat] / 2.0)
    hit |= close
    along = np.where(close, 0.0, along)
    return boat[hit], along[hit], left[hit], wide[hit], bow[hit]


def near_pairs(pos: Array, far: Array, obstacles: Obstacles, rows: Rows) -> tuple[Rows, Rows]:
    """(boat, obstacle) pairs closer than `far` (N,) to each other."""
    xy = obstacles.xy.astype(np.float32)  # a coarse test: float32 halves the traffic
    dx = np.subtract.outer(pos[rows, 0].astype(np.float32), xy[:, 0])  # (n, M), contiguous
    dy = np.subtract.outer(pos[rows, 1].astype(np.float32), xy[:, 1])
    dx *= dx
    dy *= dy
    dx += dy
    i, j = np.nonzero(dx < ((far[rows] + 1.0) ** 2).astype(np.float32)[:, None])
    return rows[i], j


def _on_arc(ahead: Array, left: Array, curvature: Array) -> tuple[Array, Array]:
    """Where an obstacle lies along the arc a boat is on (boat frame: ahead, left): the
    distance along it to the obstacle's abeam point, and its offset to the left of it."""
    bent = np.abs(curvature) > 1e-3  # straighter than a 1 km radius: a line
    k = np.where(bent, curvature, 1.0)
    radius = 1.0 / k  # signed: the centre is at (0, radius)
    dx, dy = ahead, left - radius
    turned = np.arctan2(dx, -dy * np.sign(k)) % (2 * np.pi)  # angle gone round the centre
    along = np.where(bent, turned * np.abs(radius), ahead)
    off = np.where(bent, np.sign(k) * (np.abs(radius) - np.hypot(dx, dy)), left)
    return along, off
