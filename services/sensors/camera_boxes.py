"""2D bounding boxes of every visible instance, with KITTI-style truncated/occluded flags.

The visible box comes from the instance mask itself (what a labeller would draw, and the
mask follows the body's shape), computed for all instances at once with bincount histograms
of occupied columns and rows, so a frame with many boats costs one pass over its labelled
pixels and no Python loop per pixel. The flags compare it with the WHOLE body:
- truncated: the projected body leaves the image (or part of it is behind the camera): its
  box is the box of its shape's outline points (Scene.outlines) projected by the pinhole;
- occluded: fewer visible pixels than `fraction` x its silhouette (their share is the third
  flag, in percent), the pixels whose rays
  meet its shape above the waterline whatever is in front (Scene.cast(silhouettes=True)),
  counted within the image like the visible ones. A box's area would not do: a catamaran
  seen bow-on fills a third of its box, the gap between its hulls being water.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

F64 = NDArray[np.float64]
NEAR_M = 0.05  # corners closer than this in front of the camera count as behind it


@dataclass
class Pinhole:
    """Intrinsics of the optical frame (z forward, x right, y down), pixel centres at +0.5."""

    width: int
    height: int
    fx: float
    fy: float
    cx: float
    cy: float


@dataclass
class Visible:
    """Per visible instance: id, class, box [x0, y0, x1, y1) in pixels, pixel count."""

    ids: NDArray[np.intp]
    cls: NDArray[np.uint8]
    box: F64
    count: NDArray[np.intp]


def visible_boxes(instance: NDArray[np.integer], cls: NDArray[np.uint8]) -> Visible:
    """The boxes of the instance mask (H, W); instance 0 is background."""
    h, w = instance.shape
    flat = instance.ravel()
    idx = np.flatnonzero(flat)
    if idx.size == 0:
        return Visible(
            np.empty(0, np.intp), np.empty(0, np.uint8), np.empty((0, 4)), np.empty(0, np.intp)
        )
    ids_px = flat[idx].astype(np.intp)
    ids = np.flatnonzero(np.bincount(ids_px))
    label = np.zeros(int(ids[-1]) + 1, dtype=np.intp)
    label[ids] = np.arange(ids.size)
    lab = label[ids_px]
    k = ids.size
    row, col = np.divmod(idx, w)
    cols = np.bincount(lab * w + col, minlength=k * w).reshape(k, w) > 0
    rows = np.bincount(lab * h + row, minlength=k * h).reshape(k, h) > 0
    x0, x1 = np.argmax(cols, axis=1), w - np.argmax(cols[:, ::-1], axis=1)
    y0, y1 = np.argmax(rows, axis=1), h - np.argmax(rows[:, ::-1], axis=1)
    cls_of = np.zeros(k, dtype=np.uint8)
    cls_of[lab] = cls.ravel()[idx]
    box = np.stack([x0, y0, x1, y1], axis=1).astype(np.float64)
    return Visible(ids, cls_of, box, np.bincount(lab, minlength=k))


def projected_boxes(corners_cam: F64, cam: Pinhole) -> tuple[F64, NDArray[np.bool_]]:
    """Boxes (K, 4) of K sets of 8 corners in the optical frame, and whether any corner is
    behind the camera (then the box is meaningless and the body is truncated)."""
    z = corners_cam[..., 2]
    behind: NDArray[np.bool_] = np.asarray((z < NEAR_M).any(axis=1))
    zs = np.where(z < NEAR_M, NEAR_M, z)
    u = cam.fx * corners_cam[..., 0] / zs + cam.cx
    v = cam.fy * corners_cam[..., 1] / zs + cam.cy
    box = np.stack([u.min(axis=1), v.min(axis=1), u.max(axis=1), v.max(axis=1)], axis=1)
    return box, behind


def flags(
    vis: Visible,
    full: F64,
    behind: NDArray[np.bool_],
    silhouette: NDArray[np.integer],
    *,
    cam: Pinhole,
    fraction: float,
) -> NDArray[np.uint8]:
    """(K, 3) uint8 [truncated, occluded, visible %] of the visible instances, given their
    full boxes and silhouettes (pixels): the percentage is of the silhouette's pixels in the
    image that are seen (a user filters by it, as nuScenes' visibility levels)."""
    out_of_image = (
        (full[:, 0] < 0) | (full[:, 1] < 0) | (full[:, 2] > cam.width) | (full[:, 3] > cam.height)
    )
    truncated = behind | out_of_image
    occluded = vis.count < fraction * silhouette
    seen = np.minimum(np.rint(100.0 * vis.count / np.maximum(silhouette, 1)), 100.0)
    return np.stack([truncated, occluded, seen], axis=1).astype(np.uint8)


EDGES = np.array([(a, a | bit) for a in range(8) for bit in (1, 2, 4) if not a & bit])
"""The 12 edges of a box whose corners are numbered by bits (x, y, z) as Scene.corners does."""
FRONT_M = 1e-6  # the plane the box is clipped to: points any ray can reach lie beyond it


def _pixel_rects(corners_cam: F64, cam: Pinhole) -> F64:
    """(K, 4) image rectangles [x0, y0, x1, y1] holding the part of each box in front of the
    camera: its corners beyond the plane z = FRONT_M plus its edges' crossings of that plane
    (the clipped box is convex, so it projects inside the rectangle of these points)."""
    a, b = corners_cam[:, EDGES[:, 0]], corners_cam[:, EDGES[:, 1]]  # (K, 12, 3)
    za, zb = a[..., 2], b[..., 2]
    crossing = ((za < FRONT_M) != (zb < FRONT_M))[..., None]
    with np.errstate(divide="ignore", invalid="ignore"):  # non-crossing edges: masked below
        t = (FRONT_M - za) / (zb - za)
        cut = np.where(crossing, a + t[..., None] * (b - a), np.nan)
    front = np.where(corners_cam[..., 2:] >= FRONT_M, corners_cam, np.nan)
    pts = np.concatenate([front, cut], axis=1)
    z = np.maximum(pts[..., 2], FRONT_M)
    u = cam.fx * pts[..., 0] / z + cam.cx
    v = cam.fy * pts[..., 1] / z + cam.cy
    big = 4.0 * (cam.width + cam.height)  # keep huge projections finite and off the image
    u, v = np.clip(u, -big, big), np.clip(v, -big, big)
    with np.errstate(invalid="ignore"):
        return np.stack(
            [
                np.fmin.reduce(u, 1),
                np.fmin.reduce(v, 1),
                np.fmax.reduce(u, 1),
                np.fmax.reduce(v, 1),
            ],
            axis=1,
        )


def candidate_rays(corners_cam: F64, cam: Pinhole) -> tuple[NDArray[np.intp], NDArray[np.intp]]:
    """(pixel, body) pairs for every pixel whose ray may meet a body's box, so the scene tests
    each body against its few pixels instead of every pixel against every body.

    Conservative: each box clipped to the half-space in front of the camera projects inside
    `_pixel_rects` (widened by a pixel); a box wholly behind the camera (or not posed yet,
    NaN) gets no pixel.
    """
    rect = _pixel_rects(corners_cam, cam)
    size = np.array([cam.width, cam.height])
    lo = np.clip(np.floor(rect[:, :2]) - 1, 0, size)
    hi = np.clip(np.ceil(rect[:, 2:]) + 2, 0, size)
    keep = np.flatnonzero(np.isfinite(rect).all(axis=1) & (hi > lo).all(axis=1))
    lo, hi = lo[keep].astype(np.intp), hi[keep].astype(np.intp)  # NaN rows are dropped
    width = hi[:, 0] - lo[:, 0]
    count = width * (hi[:, 1] - lo[:, 1])  # each body's rectangle, row-major, one after another
    j = np.arange(count.sum()) - np.repeat(np.cumsum(count) - count, count)
    row, col = np.divmod(j, np.repeat(width, count))
    pixels = (np.repeat(lo[:, 1], count) + row) * cam.width + np.repeat(lo[:, 0], count) + col
    return pixels, np.repeat(keep, count)
