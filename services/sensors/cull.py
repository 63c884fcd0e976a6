"""Which (ray, body) pairs can meet: the cheap pre-test before the slab test of each box.

A pair left out here is a hit lost, so every test is conservative; a pair let through only
costs a slab test. Rays from ONE origin (a radar, any caller) are tested against each body's
corner cone (the cone from the origin about the body's centre that holds its 8 corners); a
LiDAR, whose beams are a fixed grid, gets its pairs from the cones alone (`grid_pairs`).
Testing every ray against every body in range is a (rays x bodies) product, ~1 ms for a
32 x 512 scan and 16 bodies in range, almost all of it spent on pairs that are far apart.
So neighbouring rays (consecutive in the caller's order: a LiDAR channel's columns, a
camera row) are first grouped in CHUNK-ray bundles with a bounding cone of their own: two
cones can share a direction only if the angle between their axes is at most the sum of
their half-angles, and only the rays of bundles that pass are tested one by one.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

F64 = NDArray[np.float64]
Pairs = tuple[NDArray[np.intp], NDArray[np.intp]]
CHUNK = 16  # rays per bundle: a LiDAR bundle spans ~11 deg of azimuth at 512 columns
MIN_RAYS = 1024  # fewer rays (a radar's few beams): the full product is cheaper
SLACK_RAD = 1e-6  # angles are compared with this margin for rounding


@dataclass
class Cones:
    """Per body in range (`body`: index in Scene.bodies): the vector from the origin to its
    box centre (`axis`, of length `dist`) and the cos of the half-angle of the cone about it
    that holds the box (-1: every direction)."""

    body: NDArray[np.intp]
    axis: F64
    dist: F64
    cos_half: F64


def corner_cone(rel: F64, oc: F64, dist: F64) -> F64:
    """cos of the half-angle of the cone from the origin about each body's centre (`oc`, of
    length `dist`) that holds its 8 corners (`rel` (K, 8, 3), from the origin), so holds the
    box (-1: every direction, when that cone is not convex). Tighter than the bounding
    sphere, and still a cull when the origin is inside the sphere (a LiDAR above its own
    hull), where the sphere test passes every ray."""
    cos = np.einsum("kcj,kj->kc", rel, oc) / (np.linalg.norm(rel, axis=2) * dist[:, None] + 1e-300)
    cos_half = cos.min(axis=1) - 1e-9
    return np.where(cos_half > 0.0, cos_half, -1.0)


def cone_pairs(d: F64, axis: F64, dist: F64, cos_half: F64) -> Pairs:
    """(ray, body) pairs, sorted by ray then body, with d . axis >= cos_half * dist (axis:
    origin -> body centre, of length `dist`; cos_half -1: every direction)."""
    n = d.shape[0]
    if n < MIN_RAYS:
        return _sorted(*np.nonzero(np.dot(d, axis.T) >= cos_half * dist))
    m = n - n % CHUNK
    rays, body = _bundle_pairs(d[:m], axis / dist[:, None], cos_half)
    if m < n:  # the last, partial bundle: every ray against every body
        tail, k = np.nonzero(np.ones((n - m, axis.shape[0]), dtype=bool))
        rays, body = np.concatenate([rays, tail + m]), np.concatenate([body, k])
    ok = np.einsum("pj,pj->p", d[rays], axis[body]) >= cos_half[body] * dist[body]
    return _sorted(rays[ok], body[ok])


def _bundle_pairs(d: F64, unit_axis: F64, cos_half: F64) -> Pairs:
    """Every (ray, body) pair of the bundles whose bounding cone meets the body's cone.

    A bundle's axis is its middle ray and its half-angle the widest angle from it to any
    of its rays. The cones meet if apart <= spread + width, tested as cos(apart) >=
    cos(spread + width) by the angle-sum formula: no arccos over the (bundles x bodies)."""
    bundles = d.reshape(-1, CHUNK, 3)
    centre = bundles[:, CHUNK // 2]  # unit: the rays are normalised
    cos_in = np.matmul(bundles, centre[:, :, None])[:, :, 0].T.copy().min(axis=0)  # fast min
    spread = np.arccos(np.clip(cos_in, -1.0, 1.0)) + SLACK_RAD  # bundle half-angle
    width = np.arccos(np.clip(cos_half, -1.0, 1.0))  # body half-angle (pi: every direction)
    cos_sum = np.outer(np.cos(spread), np.cos(width)) - np.outer(np.sin(spread), np.sin(width))
    wide = spread[:, None] + width[None, :] >= np.pi  # the cones cover every direction
    # negated test: a NaN keeps the pair
    keep = ~(np.dot(centre, unit_axis.T) < cos_sum) | wide
    g, k = np.nonzero(keep)
    rays = (g[:, None] * CHUNK + np.arange(CHUNK)).ravel()
    return rays, np.repeat(k, CHUNK)


def grid_pairs(unit_axis: F64, cos_half: F64, elevations: F64, columns: int) -> Pairs:
    """(ray, body) pairs, sorted by ray then body, of a spinning sensor's grid (ray
    c * columns + j at elevation elevations[c], azimuth 2 pi j / columns, in the frame of
    `unit_axis`) that may lie in each body's cone, without a pass over the rays.

    For a ray at elevation e and a cone axis at elevation e0, azimuth a0, the ray is inside
    the cone where cos e cos e0 cos(a - a0) + sin e sin e0 >= cos_half: per channel, an
    azimuth interval about a0 of half-width arccos(q). It is widened by SLACK_RAD and
    rounded outward to whole columns; the slab test that follows is exact."""
    e0 = np.arcsin(np.clip(unit_axis[:, 2], -1.0, 1.0))[:, None]  # (K, 1)
    a0 = np.arctan2(unit_axis[:, 1], unit_axis[:, 0])[:, None]
    e = np.asarray(elevations, dtype=np.float64)[None, :]  # (1, C)
    scale, offset = np.cos(e) * np.cos(e0), np.sin(e) * np.sin(e0)  # (K, C)
    low = cos_half[:, None] - offset  # needed: scale cos(a - a0) >= low
    flat = scale <= 1e-12  # a vertical axis or channel: inside for every azimuth, or none
    with np.errstate(divide="ignore", invalid="ignore"):
        q = np.where(flat, 0.0, low / np.where(flat, 1.0, scale))
    every = (cos_half[:, None] <= -1.0) | np.where(flat, low <= 1e-9, q <= -1.0)
    none = ~every & (flat | (q > 1.0 + 1e-9))
    width = np.where(every, np.pi, np.arccos(np.clip(q, -1.0, 1.0)) + SLACK_RAD)
    width[none] = -1.0
    step = 2.0 * np.pi / columns
    first = np.floor((a0 - width) / step).astype(np.intp)
    count = np.minimum(np.ceil((a0 + width) / step).astype(np.intp) - first + 1, columns)
    count = np.where(width < 0.0, 0, count)
    k, c = np.nonzero(count > 0)
    n = count[k, c]
    ramp = np.arange(n.sum()) - np.repeat(np.cumsum(n) - n, n)  # 0.. n-1 per (body, channel)
    column = (np.repeat(first[k, c], n) + ramp) % columns
    return _sorted(np.repeat(c, n) * columns + column, np.repeat(k, n))


def sphere_pairs(o: F64, d: F64, centre: F64, radius: F64, max_range: float) -> Pairs:
    """(ray, body) pairs whose ray (own origin each) passes within the bounding sphere."""
    tc = np.dot(d, centre.T) - np.sum(d * o, axis=1)[:, None]
    oc2 = (
        np.sum(centre * centre, axis=1)[None, :]
        - 2.0 * np.dot(o, centre.T)
        + np.sum(o * o, axis=1)[:, None]
    )
    r = radius
    near = (oc2 - tc * tc <= r * r) & (tc >= -r) & (tc - r <= max_range)
    ray_i, k = np.nonzero(near)
    return ray_i, k


def _sorted(rays: NDArray[np.intp], body: NDArray[np.intp]) -> Pairs:
    order = np.lexsort((body, rays))
    return rays[order], body[order]
