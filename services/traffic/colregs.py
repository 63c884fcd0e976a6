"""Boats meeting boats: each picks, from a few course changes and speeds, the one that keeps
clear at least cost, under the rules of the road.

Why: the corridor rule (avoid.py) let each boat of a pair react to where the other was now.
Two boats closing at 4 m/s both turned, each to the side the other bore on, that side
changed as they turned, and neither slowed: in Table II's 100-boat cell 33 pairs of boats
touched in a minute. This is scenario-based collision avoidance (Johansen, Perez and
Cristofaro 2016, "Ship collision avoidance and COLREGS compliance using simulation-based
control behavior selection"), one step of it at every guidance tick, for all boats at once:
- candidates: course changes of OFFSETS from the boat's course, each at a part of its speed
  (SPEEDS: of the speed its law resumes, for a boat that has slowed: at its speed left, a
  slowed boat's turns went nowhere, and two boats head-on at 2.5 m/s stopped bow to bow);
  the first is the boat's own law unchanged (a boat whose law meets no hazard
  keeps it, so most boats weigh nothing);
- each candidate against each other boat under way near it: the closest point of approach
  (CPA), each boat on the arc it is turning on (predict.py: the own law's turn for the
  first candidate, a held new course for the others, the other boat's turn rate now); a
  CPA closer than both footprints plus the clearance within `horizon_s` is a hazard,
  costlier the sooner it comes;
- the rules of the road (COLREGs 13-17) as costs: a boat that gives way (the other is
  head-on, crosses from starboard, or is being overtaken by it) must not turn to port, and
  head-on must turn to starboard (slowing alone had won: it pushed the hazard out); one
  that stands on (the other crosses from its port side or overtakes it) pays STAND_ON for
  leaving its course and speed until the hazard is nearer than URGENT of the horizon, so
  the giving-way boat acts first (rules 16, 17);
- the cost of leaving its own law (the bigger the change the dearer, port dearer than
  starboard), and of turning the other way from its last pick (no dithering).
The least total wins. Both boats of a pair read the same geometry, so their roles agree.

Measured over three seeds of that cell (60 s each, plan-view hull boxes at 10 Hz): 90 pairs
touched before, 42 with straight-line CPAs, 6 with arcs (3, 1 and 2 a seed, 4 of them in
the first 4 s, between boats placed close together at rest), 1 with starts 10 m further
apart (traffic_plan.START_ROOM_M); some pair was touching in 36-47 % of the samples before,
0-1 % now. STAND_ON: with 5 the stand-on boat acted almost
as soon as the giver (9 pairs), with 100 it held on into the meeting (33 pairs): circling
boats are not the straight-line movers rule 17 has in mind, and a stand-on boat must be
free to act once the hazard is about 5 s away. Tried and not kept, with straight-line CPAs,
each worse over the same seeds: holding a give-way until the range opens (75 pairs
against 42), candidates only at full speed (51), a longer or shorter horizon (64, 44), and
planning at 5 or 2 Hz (60, 69).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from catabot.world.rotations import wrap
from services.traffic.predict import F32, Movers, closest, paths, sample_times

Array = NDArray[np.float64]
Rows = NDArray[np.intp]
_DEG = np.radians([0.0, -15.0, 15.0, -30.0, 30.0, -45.0, 45.0, -60.0, 60.0, -90.0, 90.0])
# Course changes (to port positive), each at full and half speed, and stopping (a stopped
# boat's course does not matter).
OFFSETS = np.append(np.repeat(_DEG, 2), 0.0)
SPEEDS = np.append(np.tile([1.0, 0.5], len(_DEG)), 0.0)
_ALONG, _ACROSS = SPEEDS * np.cos(OFFSETS), SPEEDS * np.sin(OFFSETS)  # in the boat's axes
HEAD_ON = np.radians(15.0)  # the other boat this close to dead ahead ...
RECIPROCAL = np.radians(30.0)  # ... on a course this close to the reverse of ours
ABEAM_AFT = np.radians(112.5)  # 22.5 degrees abaft the beam: a stern light's arc ends
URGENT = 0.35  # a stand-on boat may act when the hazard is nearer than this part of the horizon
ADRIFT_MPS = 0.5  # a boat slower than this has no course to read: the other one gives way
HAZARD, WRONG_WAY, STAND_ON = 100.0, 20.0, 30.0  # costs (a hazard's at its soonest)
TURN, SLOW, PORT, SWITCH = 4.0, 3.0, 1.0, 5.0  # costs per radian / per part of speed / flat


def choose(
    own: Movers,
    other: Movers,
    pairs: tuple[Rows, Rows],
    *,
    horizon_s: float,
    last: NDArray[np.intp],
) -> NDArray[np.intp]:
    """Each boat's candidate (an index into OFFSETS and SPEEDS; 0: its own law).

    own: the boats choosing (N rows), their turn rates their own laws', their sizes their
    footprints plus the clearance; other: the boats under way they meet (M rows, turning
    as they are now); pairs: (own row, other row) pairs near enough to matter, sorted by
    own row, never a boat with itself; `last` (N,): each boat's last pick."""
    n, t = len(own.xy), sample_times(horizon_s)
    pick = np.zeros(n, dtype=np.intp)
    boat, obs, rel, wide = _within_reach(own, other, pairs, horizon_s)
    if boat.size == 0:  # nobody near enough to meet: every boat keeps its law
        return pick
    theirs, law = paths(other, t), paths(own, t)
    theirs = (theirs[0][obs], theirs[1][obs])  # (P, T) each
    law = (law[0][boat, None], law[1][boat, None])  # (P, 1, T) each
    _, gap2 = closest(rel, theirs, law, t)
    busy = np.zeros(n, dtype=bool)
    busy[boat[gap2[:, 0] < wide * wide]] = True
    mine = busy[boat]
    if mine.any():
        rows = np.flatnonzero(busy)
        paired = (boat[mine], obs[mine])
        ways = (theirs[0][mine], theirs[1][mine]), (law[0][mine], law[1][mine])
        cost = _costs(own, other, paired, (rel[mine], wide[mine]), ways, t)
        cost += SWITCH * (np.sign(OFFSETS)[None, :] * np.sign(OFFSETS[last])[:, None] < 0.0)
        pick[rows] = np.argmin(cost[rows], axis=1)
    return pick


def _within_reach(
    own: Movers, other: Movers, pairs: tuple[Rows, Rows], horizon_s: float
) -> tuple[Rows, Rows, Array, Array]:
    """The pairs that can meet within the horizon at their speeds (no candidate is faster
    than the boat goes now), with their offsets and both footprints plus the clearance."""
    boat, obs = pairs
    rel = other.xy[obs] - own.xy[boat]
    wide = own.size[boat] + other.size[obs]
    speeds = np.hypot(*own.velocity.T)[boat] + np.hypot(*other.velocity.T)[obs]
    near = np.hypot(rel[:, 0], rel[:, 1]) < wide + speeds * horizon_s
    return boat[near], obs[near], rel[near], wide[near]


def _costs(
    own: Movers,
    other: Movers,
    pairs: tuple[Rows, Rows],
    apart: tuple[Array, Array],
    ways: tuple[tuple[F32, F32], tuple[F32, F32]],
    t: Array,
) -> Array:
    """(N, K): each candidate's cost for each boat (rows of boats without pairs: zero
    hazard). `apart`: each pair's offset and both footprints plus the clearance; `ways`:
    the other boat's displacements and this one's on its own law's arc. A candidate that
    changes course holds the new one; candidate 0 is the law."""
    boat, obs = pairs
    (rel, wide), (theirs, law) = apart, ways
    speed = np.hypot(*own.velocity.T)[boat][:, None]
    c, s = np.cos(own.course[boat])[:, None], np.sin(own.course[boat])[:, None]
    vx = (speed * (c * _ALONG - s * _ACROSS)).astype(np.float32)  # (P, K): each course's
    vy = (speed * (s * _ALONG + c * _ACROSS)).astype(np.float32)
    t32 = t.astype(np.float32)
    mine_x, mine_y = vx[..., None] * t32, vy[..., None] * t32  # (P, K, T)
    mine_x[:, :1], mine_y[:, :1] = law
    soon, gap2 = closest(rel, theirs, (mine_x, mine_y), t)
    hazard = gap2 < (wide * wide)[:, None]
    horizon_s = float(t[-1])
    pair = np.where(hazard, HAZARD * (1.0 - soon / horizon_s), 0.0)
    now = np.flatnonzero(hazard[:, 0])  # the rules bind the pairs that are a hazard now
    sub = (boat[now], obs[now])
    pair[now] += _rules(own, other, sub, rel[now], soon_now=soon[now, 0], horizon_s=horizon_s)
    cost = np.zeros((len(own.xy), len(OFFSETS)))
    first = np.flatnonzero(np.diff(boat, prepend=-1))  # pairs come sorted by boat
    cost[boat[first]] = np.maximum.reduceat(pair, first, axis=0)
    return cost + TURN * np.abs(OFFSETS) + SLOW * (1.0 - SPEEDS) + PORT * (OFFSETS > 0.0)


def _rules(
    own: Movers,
    other: Movers,
    pairs: tuple[Rows, Rows],
    rel: Array,
    *,
    soon_now: Array,
    horizon_s: float,
) -> Array:
    """(P, K) costs of breaking the rules in pairs that are a hazard as things go now."""
    boat, obs = pairs
    chi = own.course[boat]
    bearing = wrap(np.arctan2(rel[:, 1], rel[:, 0]) - chi)  # + to port
    theirs = other.course[obs]
    seen_from_them = wrap(np.arctan2(-rel[:, 1], -rel[:, 0]) - theirs)
    head_on = (np.abs(bearing) < HEAD_ON) & (np.abs(wrap(theirs - chi - np.pi)) < RECIPROCAL)
    from_starboard = (bearing < 0.0) & (bearing > -ABEAM_AFT)
    overtaking = (np.abs(seen_from_them) > ABEAM_AFT) & (np.abs(bearing) < np.pi - ABEAM_AFT)
    adrift = np.hypot(*other.velocity[obs].T) < ADRIFT_MPS
    gives = head_on | from_starboard | overtaking | adrift
    stands = ~gives & (soon_now > URGENT * horizon_s)
    changed = (OFFSETS != 0.0) | (SPEEDS != 1.0)
    wrong = (gives[:, None] & (OFFSETS > 0.0)) | (head_on[:, None] & (OFFSETS >= 0.0))
    return np.asarray(WRONG_WAY * wrong + STAND_ON * (stands[:, None] & changed))
