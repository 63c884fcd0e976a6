"""Targets narrower than the gap between a radar beam's rays: each beam sees what its width
holds, as a real antenna does.

Why: a beam is `sub_rays` rays across its width (3 across 1.5 deg: 0.5 deg apart), so a
target narrower than that gap at its range could pass between them. An audit moved a 0.44 m
buoy round the antenna: at 20-100 m every bearing showed it; at 150 m 53 of 60, at 200 m 40
and at 240 m 33, and where it showed it was on one beam, where a 1.5 deg beam sees it on
two. So a body narrower in plan than that gap, out of the antenna's near blind zone
(`fan_min_range_m`), whose centre bearing lies within a beam's width but that none of the
beam's rays met, is cast again in that beam: at its centre bearing, by the beam's own
elevations that can reach its box; its hits on that body are the beam's echo of it. A body
a ray met keeps that echo alone (no target counts twice), a wider one the rays did not meet
is hidden (they would have), so a scene whose bodies the rays meet gives the returns it
gave before, and the fill's range noise comes from a stream of its own (the main stream
stays aligned).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from catabot.world.rotations import wrap
from services.sensors.cull import Cones

F64 = NDArray[np.float64]
Ints = NDArray[np.intp]


@dataclass(frozen=True)
class Beams:
    """One sample's beams: map bearings (B,), their width and the gap between their rays
    (rad), their elevations (E,), and the instance each ray met (B, rays)."""

    bearing: F64
    width: float
    gap: float
    elevations: F64
    met: NDArray[np.int32]


@dataclass(frozen=True)
class Fill:
    """The rays to cast again: the beam each belongs to, the instance it looks for, and
    its unit direction (map frame)."""

    beam: Ints
    instance: NDArray[np.int32]
    dirs: F64


NO_FILL = Fill(np.empty(0, np.intp), np.empty(0, np.int32), np.empty((0, 3)))


def fill(
    origin: F64, cones: Cones, corners: F64, instances: NDArray[np.int32], beams: Beams,
    *, near_m: float,
) -> Fill:  # fmt: skip
    """The rays for the thin bodies in range (`cones`; `corners` (n, 8, 3) of every body,
    `instances` (n,)) that a beam's width holds and its rays missed."""
    centre = np.arctan2(cones.axis[:, 1], cones.axis[:, 0])
    beam, k = np.nonzero(np.abs(wrap(centre[None, :] - beams.bearing[:, None])) <= beams.width / 2)
    held = np.unique(k)  # the bodies some beam of this sample holds: a few of those in range
    rel = corners[cones.body[held]] - origin  # (H, 8, 3)
    plan = np.hypot(cones.axis[held, 0], cones.axis[held, 1])
    spread = np.abs(wrap(np.arctan2(rel[..., 1], rel[..., 0]) - centre[held, None])).max(axis=1)
    thin = np.zeros(centre.size, dtype=bool)
    thin[held] = (plan >= near_m) & (2.0 * spread < beams.gap)
    if not thin.any():  # most samples: nothing to fill, a tenth of a millisecond spared
        return NO_FILL
    inst = instances[cones.body]
    keep = thin[k] & ~(beams.met[beam] == inst[k, None]).any(axis=1)
    beam, k = beam[keep], k[keep]
    rise = np.full((centre.size, 2), np.nan)  # each held body's span of elevations
    up = np.arctan2(rel[..., 2], np.hypot(rel[..., 0], rel[..., 1]))
    rise[held] = np.stack([up.min(axis=1), up.max(axis=1)], axis=1)
    e = beams.elevations[None, :]
    pair, el = np.nonzero((e >= rise[k, :1]) & (e <= rise[k, 1:]))  # rays through the box
    dirs = directions(centre[k][pair], beams.elevations[el])
    return Fill(beam[pair], inst[k][pair], dirs)


def directions(bearing: F64, elevation: F64) -> F64:
    """Unit directions (..., 3) at map bearings and elevations (rad), broadcast together."""
    b, e = np.broadcast_arrays(bearing, elevation)
    return np.stack([np.cos(e) * np.cos(b), np.cos(e) * np.sin(b), np.sin(e)], axis=-1)
