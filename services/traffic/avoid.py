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
- Corridor: a buoy on the arc a boat's own law turns it on, within lookahead_s at its
  speed and closer to that arc than both footprints plus the clearance, makes it take the
  clear arc nearest its law's among nine turns from full starboard to full port (to
  starboard on a tie; clear by half as much again, for the boat's lag in turning); with
  none clear, the one that passes its obstacles widest. First, anything closer than the
  corridor's half-width anywhere but astern (a boat turning at low speed, two boats
  alongside), buoy or boat, which it simply turns away from, backing off while it lies
  under the bow. The boat's own law resumes when its arc is clear. The
  marks on a boat's own path are left to the first rule. Boats under way ahead are not
  corridor obstacles: reacting to where another boat is now, both boats of a pair turned,
  each to the side the other bore on, and still met; colregs.py gives such meetings to one
  of the two, and its pick is what the corridor checks (behaviours.py: the rules first).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

Array = NDArray[np.float64]
Rows = NDArray[np.intp]
MARK_M = 0.5  # a waypoint this close to a buoy's anchor is that buoy's mark
PAIRS = 250_000  # boats x obstacles compared at once (bounds the temporaries)
TURNS = np.linspace(-1.0, 1.0, 9)  # the turns a blocked boat may take, parts of its full rate
MARGIN = 1.5  # a turn taken instead must pass this many corridor half-widths clear


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
    home: Array | None = None  # (M, 2) where each was at the start (a buoy's anchor); None: xy

    @property
    def moored_at(self) -> Array:
        """Where each is moored (`home`), else where it is: how a mark's buoy is known."""
        return self.xy if self.home is None else self.home

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


def drifted(points: Array, obstacles: Obstacles | None) -> Array:
    """Where the buoy moored at each of `points` (k, 2) rides now, the point itself where no
    buoy is: a mark is rounded where its buoy is, metres off its anchor in a current."""
    if obstacles is None or not len(points):
        return points
    fixed = np.flatnonzero(~obstacles.under_way)
    if fixed.size == 0:
        return points
    gap = points[:, None, :] - obstacles.moored_at[fixed][None, :, :]
    d2 = gap[..., 0] ** 2 + gap[..., 1] ** 2
    nearest = d2.argmin(axis=1)
    hit = d2[np.arange(len(points)), nearest] < MARK_M**2
    return np.where(hit[:, None], obstacles.xy[fixed[nearest]], points)


def mark_aim(pos: Array, mark: Array, pass_m: Array) -> Array:
    """The point `pass_m` to the right of each boat's line of sight to its mark."""
    los = mark - pos
    dist = np.maximum(np.hypot(los[:, 0], los[:, 1]), 1e-9)
    right = np.column_stack((los[:, 1], -los[:, 0])) / dist[:, None]
    return np.asarray(mark + pass_m[:, None] * right)


def corridor_turn(
    pos: Array, chi: Array, turn: Array, full_bend: Array, reach: Array, width: Array,
    obstacles: Obstacles, marks: Array,
) -> tuple[Array, NDArray[np.bool_]]:  # fmt: skip
    """Per boat: the turn that keeps its corridor clear, a part of its full rate (+ to port),
    nan where its own law's turn (`turn`, the same units) already does; and whether it must
    back off, an obstacle being under its bow. `full_bend` (N,): the curvature of a full
    turn at its speed (1/m); `reach` (N,) metres along each arc; `width` (N,) its footprint
    plus the clearance either side; marks (N, K, 2): the marks on a boat's own path (nan:
    none), which it rounds instead."""
    out, stop = np.full(len(pos), np.nan), np.zeros(len(pos), dtype=bool)
    step = max(1, PAIRS // max(len(obstacles.xy) * len(TURNS), 1))
    for s in range(0, len(pos), step):
        rows = np.arange(s, min(s + step, len(pos)))
        boat, obs = near_pairs(pos, reach + width + obstacles.radius.max(), obstacles, rows)
        boat, obs = _others(boat, obs, (pos, width), obstacles, marks)
        ahead, left, wide = _seen(boat, obs, pos, chi, width, obstacles)
        near = _close(out, stop, boat, (ahead, left, wide), width)
        far = ~near[boat] & ~obstacles.under_way[obs]  # boats meeting boats: colregs.py
        arcs = np.append(TURNS, 0.0)[None, :] * full_bend[boat[far], None]
        arcs[:, -1] = turn[boat[far]] * full_bend[boat[far]]  # the last: the law's own arc
        lie = (ahead[far], left[far], wide[far])
        _clear_arc(out, boat[far], lie, arcs, (reach, turn))
    return out, stop


def _seen(
    boat: Rows, obs: Rows, pos: Array, chi: Array, width: Array, obstacles: Obstacles
) -> tuple[Array, Array, Array]:
    """Each pair's obstacle in the boat's frame (ahead, to the left) and the corridor's
    half-width there (both footprints plus the clearance)."""
    rel = obstacles.xy[obs] - pos[boat]
    cos, sin = np.cos(chi[boat]), np.sin(chi[boat])
    ahead, left = rel[:, 0] * cos + rel[:, 1] * sin, rel[:, 1] * cos - rel[:, 0] * sin
    return ahead, left, width[boat] + obstacles.radius[obs]


def _close(
    out: Array, stop: NDArray[np.bool_], boat: Rows, lie: tuple[Array, Array, Array],
    width: Array,
) -> NDArray[np.bool_]:  # fmt: skip
    """Anything closer than the corridor's half-width anywhere but astern (a boat turning
    at low speed, two boats alongside), buoy or boat: the nearest decides, a full turn
    away from the side it lies on, backing off while it is under the bow. Which boats."""
    ahead, left, wide = lie
    gap = np.hypot(ahead, left)
    close = np.flatnonzero((ahead > -width[boat]) & (gap < wide))
    near = np.zeros(len(out), dtype=bool)
    if close.size:
        order = close[np.lexsort((gap[close], boat[close]))]
        first = order[np.unique(boat[order], return_index=True)[1]]
        out[boat[first]] = np.where(left[first] < 0.0, 1.0, -1.0)
        stop[boat[first]] = (ahead[first] > 0.0) & (np.abs(left[first]) < width[boat[first]] / 2)
        near[boat[first]] = True
    return near


def _clear_arc(
    out: Array, boat: Rows, lie: tuple[Array, Array, Array], arcs: Array,
    laws: tuple[Array, Array],
) -> None:  # fmt: skip
    """Boats whose own arc meets an obstacle within reach take the clear turn nearest their
    law's, to starboard on a tie (COLREGs rule 14); with none clear, the one that passes its
    obstacles widest, at its law's speed (slowing to half speed too piled boats up: a
    trial's four seeds, 22 touches between boats against 18).
    Why not a full turn away, as before: a boat turning for its waypoint met a buoy on that
    arc, turned away, found its arc clear, turned back, and so on at every guidance tick:
    the yaw rate flipped between its limits and the boat never got there."""
    if boat.size == 0:
        return
    (ahead, left, wide), (reach, turn) = lie, laws
    along, off = _on_arc(ahead[:, None], left[:, None], arcs)
    ahead_of_it = (along > 0.0) & (along < (reach[boat] + wide)[:, None])
    rows, at = np.unique(boat, return_inverse=True)
    room = np.full((len(rows), arcs.shape[1]), np.inf)  # each arc's least |off| / corridor
    np.minimum.at(room, at, np.where(ahead_of_it, np.abs(off) / wide[:, None], np.inf))
    stuck, starboard = room[:, -1] < 1.0, 1e-6 * (TURNS > 0.0)
    cost = np.abs(TURNS[None, :] - turn[rows, None]) + starboard
    pick = np.argmin(np.where(room[:, :-1] < MARGIN, np.inf, cost), axis=1)
    walled = stuck & (room[np.arange(len(rows)), pick] < MARGIN)
    pick = np.where(walled, np.argmax(room[:, :-1] - starboard, axis=1), pick)
    out[rows[stuck]] = TURNS[pick[stuck]]


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
    gap = obstacles.moored_at[obs][:, None, :] - marks[boat]  # a buoy by its anchor, metres
    # off it in a current (pairs, K, 2)
    near = np.any(gap[..., 0] ** 2 + gap[..., 1] ** 2 < MARK_M**2, axis=1)  # nan: no mark
    mark = near & ~obstacles.under_way[obs]
    return boat[~mark], obs[~mark]


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
