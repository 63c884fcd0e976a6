"""Where two boats will be: each on the arc it is turning on, sampled over the horizon.

Why: the rules of the road (colregs.py) first predicted straight tracks, as most collision
avoidance does for ships. A circling traffic boat turns about 15 degrees a second, so a
straight line misjudged most meetings within a few seconds: 42 pairs of boats still touched
over three seeds of Table II's 100-boat cell (60 s each). Predicted along each boat's arc
(its turn rate held), 6 pairs did. There is no closed form for the closest point of
approach of two arcs, so the distance is sampled SAMPLES times over the horizon and the
least sample refined by a parabola (`closest`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

Array = NDArray[np.float64]
F32 = NDArray[np.float32]
SAMPLES = 8  # times over the horizon: 1 s apart for the default 8 s


@dataclass(frozen=True)
class Movers:
    """Boats under way at one guidance tick, in `map` (rows: boats)."""

    xy: Array  # (n, 2) m
    velocity: Array  # (n, 2) m/s over ground
    course: Array  # (n,) rad, the heading when too slow to have a course
    turn: Array  # (n,) rad/s, to port positive: each is predicted to hold this rate
    size: Array  # (n,) m: its footprint's radius, plus the clearance for a boat choosing


def arc(rate: Array, t: Array) -> tuple[Array, Array]:
    """Coefficients (a, b), shape rate.shape + t.shape, of the displacement after time t of
    a boat at velocity v turning at `rate`: a v + b v', v' being v turned 90 degrees to
    port. A straight track (rate 0) is a = t, b = 0."""
    wt = rate[..., None] * t
    straight = np.abs(wt) < 1e-9
    safe = np.where(straight, 1.0, rate[..., None])
    a = np.where(straight, t, np.sin(wt) / safe)
    b = np.where(straight, 0.5 * rate[..., None] * t * t, (1.0 - np.cos(wt)) / safe)
    return a, b


def sample_times(horizon_s: float) -> Array:
    """SAMPLES + 1 times from now to the horizon."""
    return horizon_s * np.arange(SAMPLES + 1) / SAMPLES


def paths(movers: Movers, t: Array) -> tuple[F32, F32]:
    """Each boat's displacement (x, y), (n, T) each, at times t on its arc: per boat, so
    the trigonometry is done once a boat, not once a pair. float32, as every array of
    `closest`: hundreds of metres to a tenth of a millimetre, and half the memory traffic
    of the (pairs x courses x times) arrays (choose: 1.24 -> 0.86 ms a guidance tick with
    100 boats, the same picks)."""
    a, b = arc(movers.turn, t)
    vx, vy = movers.velocity[:, :1], movers.velocity[:, 1:]
    return (a * vx - b * vy).astype(np.float32), (a * vy + b * vx).astype(np.float32)


def closest(
    rel: Array, theirs: tuple[F32, F32], mine: tuple[F32, F32], t: Array
) -> tuple[Array, Array]:
    """Time (s) of the closest approach between two boats offset by `rel` (P, 2) and the
    distance then squared, (P, K) each; theirs: the other's displacements (P, T), mine: K
    courses of action's (P, K, T), at times t (T,) from 0 on, evenly spaced. The least
    sample and its neighbours are fitted by a parabola: exact for two straight tracks (the
    squared distance is quadratic in time), close for arcs, and no sampling steps in the
    times the costs read."""
    near = rel.astype(np.float32)
    gap_x = (near[:, :1] + theirs[0])[:, None, :] - mine[0]
    gap_y = (near[:, 1:] + theirs[1])[:, None, :] - mine[1]
    gap2 = gap_x * gap_x + gap_y * gap_y
    k = np.clip(gap2.argmin(axis=-1), 1, len(t) - 2)  # a sample with neighbours
    flat = gap2.reshape(-1)  # one gather a neighbour: take_along_axis built 3 index grids
    where = np.arange(0, flat.size, len(t)).reshape(k.shape) + k
    before, at, after = flat[where - 1], flat[where], flat[where + 1]
    bend = np.maximum(before - 2.0 * at + after, 1e-12)
    step = np.clip((before - after) / (2.0 * bend), -1.0, 1.0)  # the vertex, in samples
    least = np.maximum(at + 0.5 * (after - before) * step + 0.5 * bend * step * step, 0.0)
    return (k + step) * (t[1] - t[0]), least
