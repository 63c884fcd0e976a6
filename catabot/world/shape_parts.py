"""Shape primitives into triangles (catabot/config/vessel_shape.py), with NumPy alone.

The bundled models are built from primitives at load time rather than shipped as mesh
files: a `hull` part is the buoyancy hull itself (the same centre, length, beam and height
physics floats), so the shape follows any edit of the hulls; the JSON stays the one
reviewable source of a model's geometry; nothing is added to the package data; and a process
building them needs no mesh reader (open3d is imported only for mesh files).

Every primitive is a loft: closed cross-sections (S, P, 3) along the body x axis joined by
quads, capped at both ends (fans: every section is convex), wound to face outwards. A
section may shrink to a line or a point (a stem, a cone's tip); the zero-area triangles
that leaves are dropped.
Cylinders have SEGMENTS sides with a vertex on each axis, so their bounding box is the true
cylinder's and a flat side lies at most r (1 - cos(pi / SEGMENTS)) inside it (1.8 mm for the
WAM-V's 0.213 m pontoons).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from catabot.config.vessel import Hull
from catabot.config.vessel_shape import BoxPart, CylinderPart, HullPart, Part, VHullPart

F64 = NDArray[np.float64]
I32 = NDArray[np.int32]
SEGMENTS = 24  # sides of a cylinder (a multiple of 4: a vertex on each axis)
AXES = {  # a part built along x, turned onto its axis (columns: where x, y, z go)
    "x": np.eye(3),
    "y": np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]),
    "z": np.array([[0.0, 0.0, -1.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]]),
}


def parts_mesh(parts: list[Part], hulls: list[Hull]) -> tuple[F64, I32]:
    """Vertices (V, 3) and triangles (T, 3) of every part, in the body frame."""
    meshes = [_part(p, hulls) for p in parts]
    offsets = np.cumsum([0] + [v.shape[0] for v, _ in meshes[:-1]])
    vertices = np.concatenate([v for v, _ in meshes])
    triangles = np.concatenate([t + o for (_, t), o in zip(meshes, offsets, strict=True)])
    return vertices, _without_degenerate(vertices, triangles.astype(np.int32))


def box_mesh(lo: F64, hi: F64) -> tuple[F64, I32]:
    """The box lo..hi (body frame) as triangles: a model without a shape, drawn."""
    (y, z), (width, height) = (lo[1:] + hi[1:]) / 2, hi[1:] - lo[1:]
    return loft(_sections(float(lo[0]), float(hi[0] - lo[0]), 0.0, _rectangle(y, z, width, height)))


def _part(part: Part, hulls: list[Hull]) -> tuple[F64, I32]:
    if isinstance(part, HullPart):
        return _hull(hulls[part.hull], part.bow_m)
    if isinstance(part, BoxPart):
        (x, y, z), (length, width, height) = part.center_m, part.size_m
        return loft(_sections(x - length / 2, length, 0.0, _rectangle(y, z, width, height)))
    if isinstance(part, CylinderPart):
        circle = _circle(0.0, 0.0, part.diameter_m / 2)
        vertices, triangles = loft(_sections(-part.length_m / 2, part.length_m, 0.0, circle))
        return vertices @ AXES[part.axis].T + np.asarray(part.center_m), triangles
    return _vhull(part)


def _hull(hull: Hull, bow_m: float) -> tuple[F64, I32]:
    """The buoyancy hull as physics floats it (box, or cylinder along x), bow tapered."""
    x, y, z = hull.center_m
    if hull.shape == "box":
        assert hull.height_m is not None  # the model requires it for a box
        section = _rectangle(y, z, hull.beam_m, hull.height_m)
        return loft(_sections(x - hull.length_m / 2, hull.length_m, bow_m, section))
    circle = _circle(y, z, hull.beam_m / 2)
    return loft(_sections(x - hull.length_m / 2, hull.length_m, bow_m, circle, tip=True))


def _vhull(p: VHullPart) -> tuple[F64, I32]:
    half, y = p.beam_m / 2, p.center_y_m
    yz = [(y, p.keel_z_m), (y - half, p.chine_z_m), (y - half, p.deck_z_m),
          (y + half, p.deck_z_m), (y + half, p.chine_z_m)]  # fmt: skip
    return loft(_sections(p.stern_x_m, p.length_m, p.bow_m, np.array(yz)))


def _rectangle(y: float, z: float, width: float, height: float) -> F64:
    return np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]]) * [width / 2, height / 2] + [y, z]


def _circle(y: float, z: float, radius: float) -> F64:
    a = 2.0 * np.pi * np.arange(SEGMENTS) / SEGMENTS
    return np.stack([y + radius * np.cos(a), z + radius * np.sin(a)], axis=1)


def _sections(stern_x: float, length: float, bow: float, yz: F64, *, tip: bool = False) -> F64:
    """(S, P, 3) sections along x: the full `yz` section from the stern, and, with a bow,
    one where the bow starts and the stem, where the section closes on its y centre (a
    vertical stem) or, with `tip`, on its centre (a cone's point)."""
    stem = yz.copy()
    stem[:, 0] = 0.5 * (yz[:, 0].min() + yz[:, 0].max())
    if tip:
        stem[:, 1] = 0.5 * (yz[:, 1].min() + yz[:, 1].max())
    xs, shapes = [stern_x, stern_x + length], [yz, yz]
    if bow > 0.0:
        xs, shapes = [stern_x, stern_x + length - bow, stern_x + length], [yz, yz, stem]
    return np.stack(
        [np.column_stack([np.full(len(s), x), s]) for x, s in zip(xs, shapes, strict=True)]
    )


def loft(sections: F64) -> tuple[F64, I32]:
    """A closed surface through convex sections (S, P, 3) along +x: quads between
    consecutive sections, a fan over each end, every triangle wound counter-clockwise seen
    from outside (so its right-hand normal points out: the viewer lights it)."""
    y, z = sections[0, :, 1], sections[0, :, 2]
    if np.dot(y, np.roll(z, -1)) < np.dot(np.roll(y, -1), z):  # clockwise seen from +x
        sections = sections[:, ::-1]
    s, p = sections.shape[:2]
    index = np.arange(s * p).reshape(s, p)
    a, c = index[:-1], index[1:]
    b, d = np.roll(a, -1, axis=1), np.roll(c, -1, axis=1)
    sides = np.concatenate([np.stack([a, b, d], -1), np.stack([a, d, c], -1)]).reshape(-1, 3)
    fan = np.arange(1, p - 1)
    first = np.stack([np.zeros_like(fan), fan + 1, fan], -1)
    last = np.stack([np.zeros_like(fan), fan, fan + 1], -1) + (s - 1) * p
    triangles = np.concatenate([sides, first, last]).astype(np.int32)
    return sections.reshape(-1, 3).astype(np.float64), triangles


def _without_degenerate(vertices: F64, triangles: I32) -> I32:
    """Triangles of non-zero area only (a stem or a cone's tip leaves zero-area ones)."""
    a, b, c = (vertices[triangles[:, k]] for k in range(3))
    area2 = np.linalg.norm(np.cross(b - a, c - a), axis=1)
    scale = float(np.ptp(vertices, axis=0).max()) if vertices.size else 0.0
    return triangles[area2 > 1e-12 * max(scale, 1.0) ** 2]
