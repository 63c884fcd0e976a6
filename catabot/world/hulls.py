"""Hull geometry shared by physics and the recorder: contact probes and plan-view footprints.

Physics pushes a hull off the ground at its probes (services/physics/grounding.py) and the
recorder reports a grounding when a probe is below the ground (services/recorder), so both
use these points. Two hulls collide in physics as their `hull_box` boxes; the recorder's
collision test is the same box seen from above (an oriented rectangle per body).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from catabot.config.vessel import Hull, VesselModel
from catabot.world.rotations import turn_xy, yaw_of_quaternions

Array = NDArray[np.float64]
Rows = NDArray[np.intp]
PROBE_SPACING_M = 0.5  # along and across each hull bottom
CONTACT_M = 0.01  # hull boxes this close touch (physics resolves a contact within mm)


def hull_probes(hull: Hull, spacing_m: float) -> Array:
    """Contact probe points (K, 3), body frame: a grid on the hull's underside, edges included
    (a bow corner is what touches a bank first). A cylinder gets three lines at -50, 0, 50
    degrees around its keel."""
    cx, cy, cz = hull.center_m
    n_along = min(33, max(2, math.ceil(hull.length_m / spacing_m) + 1))
    xs = np.linspace(cx - hull.length_m / 2, cx + hull.length_m / 2, n_along)
    if hull.shape == "cylinder":
        angle = np.radians([-50.0, 0.0, 50.0])
        r = hull.beam_m / 2
        ys, zs = cy + r * np.sin(angle), cz - r * np.cos(angle)
    else:
        n_across = min(9, max(2, math.ceil(hull.beam_m / spacing_m) + 1))
        ys = np.linspace(cy - hull.beam_m / 2, cy + hull.beam_m / 2, n_across)
        zs = np.full(n_across, cz - hull.vertical_extent_m / 2)
    gx, gi = np.meshgrid(xs, np.arange(len(ys)), indexing="ij")
    return np.stack([gx.ravel(), ys[gi].ravel(), zs[gi].ravel()], axis=1)


def model_probes(model: VesselModel, spacing_m: float = PROBE_SPACING_M) -> Array:
    """Every hull's probes of one model (K, 3), body frame."""
    return np.concatenate([hull_probes(h, spacing_m) for h in model.hulls])


def footprints(models: Sequence[VesselModel]) -> tuple[Array, Array]:
    """Plan-view boxes of bodies: the centre offset (N, 2, body x/y) and half extents (N, 2)
    of each model's `hull_box` (the physics collision shape) seen from above."""
    boxes = [m.hull_box() for m in models]
    lo = np.array([b[0][:2] for b in boxes]).reshape(-1, 2)
    hi = np.array([b[1][:2] for b in boxes]).reshape(-1, 2)
    return (lo + hi) / 2, (hi - lo) / 2


def box_gaps(
    centre: Array, heading: Array, half: Array, a: NDArray[np.intp], b: NDArray[np.intp]
) -> Array:
    """Separation (m) of the plan-view boxes of body pairs (a[k], b[k]): the largest gap
    along the four edge normals (separating axis theorem), <= 0 when they overlap.

    `centre` (N, 2) world box centres, `heading` (N,) yaw, `half` (N, 2) half extents.
    Exact for two boxes that face each other; where a corner is nearest it is a lower
    bound of the distance, which is all a contact test (gap <= tolerance) needs."""
    ca, sa, cb, sb = np.cos(heading[a]), np.sin(heading[a]), np.cos(heading[b]), np.sin(heading[b])
    axes = np.stack(  # (K, 4, 2): a's x and y, b's x and y
        [np.stack([ca, sa], -1), np.stack([-sa, ca], -1), np.stack([cb, sb], -1),
         np.stack([-sb, cb], -1)], axis=1)  # fmt: skip
    d = centre[b] - centre[a]
    along = np.abs(np.einsum("kj,kij->ki", d, axes))
    reach = half[a, :1] * np.abs(axes @ np.stack([ca, sa], -1)[..., None])[..., 0]
    reach += half[a, 1:] * np.abs(axes @ np.stack([-sa, ca], -1)[..., None])[..., 0]
    reach += half[b, :1] * np.abs(axes @ np.stack([cb, sb], -1)[..., None])[..., 0]
    reach += half[b, 1:] * np.abs(axes @ np.stack([-sb, cb], -1)[..., None])[..., 0]
    return np.asarray((along - reach).max(axis=1))


def boxes_touch(
    xy: Array, quat: Array, boxes: tuple[Array, Array], a: Rows, b: Rows
) -> NDArray[np.bool_]:
    """Which body pairs (a[k], b[k]) touch: their plan-view boxes within CONTACT_M. Bodies
    at `xy` (N, 2) turned by `quat` (N, 4), boxes (offset, half) as `footprints` gives them;
    headings are worked out for the bodies of the pairs only."""
    offset, half = boxes
    rows = np.unique(np.concatenate([a, b]))
    heading = np.zeros(len(xy))
    heading[rows] = yaw_of_quaternions(quat[rows])
    centre = np.array(xy, dtype=np.float64)
    centre[rows] += turn_xy(offset[rows], heading[rows])
    return np.asarray(box_gaps(centre, heading, half, a, b) <= CONTACT_M)
