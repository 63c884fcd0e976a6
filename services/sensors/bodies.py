"""The moving bodies of the ray-casting scene (vessels, boats, buoys): poses, culls, hits.

Each body is its model's shape (catabot/world/shapes.py), or the box `lo`..`hi` for a model
without one, and every body is culled as its box, in its own frame. Moving them must not
rebuild any scene, so:
- bodies out of range of every ray origin are dropped, and a cheap conservative pre-test
  leaves a few (ray, body) pairs (services/sensors/cull.py: cones from a shared origin,
  tested per bundle of rays; a camera or LiDAR passes its own pairs, from its pixel or
  beam grid);
- those pairs get the slab test against the box in the body's frame (services/sensors/
  slab.py), which is the exact hit of a body without a shape;
- the pairs that enter a shaped body's box, and only those, are cast in the body's frame
  into that model's own Embree scene, built once (services/sensors/shapes.py).
Every step is vectorised over pairs; the only Python loops run over distinct models.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from catabot.world.shapes import ShapeMesh
from services.sensors.common import (
    Nearest,
    SensorError,
    rotation_from_quaternion,
    rotations_from_quaternions,
    rows_of,
)
from services.sensors.cull import Cones, cone_pairs, corner_cone, sphere_pairs
from services.sensors.shapes import ShapeCaster
from services.sensors.slab import slab

F32 = NDArray[np.float32]
F64 = NDArray[np.float64]
Pairs = tuple[NDArray[np.intp], NDArray[np.intp]]
Poses = Mapping[str, tuple[Sequence[float], Sequence[float]]]
Vec3 = tuple[float, float, float]
CORNER_BITS = np.array([[i >> 2 & 1, i >> 1 & 1, i & 1] for i in range(8)], dtype=bool)
"""Corner i of a box takes hi on axis x, y, z where bit 2, 1, 0 of i is set."""


class SceneError(SensorError):
    """Rays or poses the scene cannot use (wrong shapes, non-finite values, unknown body)."""


@dataclass(frozen=True)
class Body:
    """A moving body: the box `lo`..`hi` in its body frame (FLU), and the `shape` inside
    that box that rays hit (None: the box itself). Bodies of one model share one shape."""

    id: str
    cls: int
    instance: int
    lo: Vec3
    hi: Vec3
    shape: ShapeMesh | None = None


class Bodies:
    """Every body's box, shape, label and pose, as arrays in `bodies` order."""

    def __init__(self, bodies: Sequence[Body]) -> None:
        self.bodies = list(bodies)
        self._index = {b.id: i for i, b in enumerate(self.bodies)}
        self._rows_ids: tuple[str, ...] = ()  # place_arrays' id list and its rows
        self._rows = np.empty(0, np.intp)
        if len(self._index) != len(self.bodies):
            raise SceneError("body ids must be unique")
        lo = np.array([b.lo for b in self.bodies], dtype=np.float64).reshape(-1, 3)
        hi = np.array([b.hi for b in self.bodies], dtype=np.float64).reshape(-1, 3)
        self._lo, self._hi = lo, hi
        self._centre_b = (lo + hi) / 2  # box centre in the body frame
        self.radius = np.linalg.norm(hi - lo, axis=1) / 2
        self._shape, self._shapes = _shapes_of(self.bodies, lo, hi)
        self._cls = np.array([b.cls for b in self.bodies], dtype=np.uint8)
        self._inst = np.array([b.instance for b in self.bodies], dtype=np.int32)
        self._inst.flags.writeable = False
        n = len(self.bodies)
        self.pos = np.full((n, 3), np.nan)  # unposed bodies are not in the scene
        self.rot = np.tile(np.eye(3), (n, 1, 1))
        self._posed: tuple[F64, F64] | None = None  # (centres, corners) of the poses now
        self._last_cones: tuple[tuple[F64, F64], tuple[bytes, float], Cones] | None = None

    def place(self, poses: Poses) -> None:
        """Every named body at once (one by one cost ~0.6 ms a tick for 100); a bad pose is
        named by the one-by-one path."""
        rows = [self._index.get(body_id, -1) for body_id in poses]
        try:
            pos = np.array([p for p, _ in poses.values()], dtype=np.float64)
            quat = np.array([q for _, q in poses.values()], dtype=np.float64)
        except (ValueError, TypeError):  # ragged: some pose has the wrong length
            pos = quat = np.empty(0)
        n = len(rows)
        rot = rotations_from_quaternions(quat) if quat.shape == (n, 4) else None
        if min(rows) < 0 or pos.shape != (n, 3) or not np.isfinite(pos).all() or rot is None:
            self._one_by_one(poses)
            return
        self.pos[rows], self.rot[rows] = pos, rot
        self._posed = None

    def place_arrays(
        self, ids: Sequence[str], position: np.ndarray, orientation: np.ndarray
    ) -> bool:
        """A `BodyStates` batch's poses, row i being `ids[i]`, with no per-body Python
        objects (rows are mapped once per id list); False, placing nothing, if a row is bad
        (the caller then names it through `place`)."""
        ids = tuple(ids)
        if self._rows_ids != ids:
            self._rows = np.array([self._index.get(b, -1) for b in ids], dtype=np.intp)
            self._rows_ids = ids
        n, rows = len(ids), self._rows
        rot = rotations_from_quaternions(orientation) if orientation.shape == (n, 4) else None
        if (
            rot is None
            or position.shape != (n, 3)
            or not np.isfinite(position).all()
            or (n and rows.min() < 0)
        ):
            return False
        self.pos[rows], self.rot[rows] = position, rot
        self._posed = None
        return True

    def _one_by_one(self, poses: Poses) -> None:
        for body_id, (position, quaternion) in poses.items():
            i = self._index.get(body_id)
            if i is None:
                raise SceneError(f"unknown body {body_id!r} (known: {sorted(self._index)})")
            p = np.asarray(position, dtype=np.float64)
            if p.shape != (3,) or not np.isfinite(p).all():
                raise SceneError(f"body {body_id!r}: position must be 3 finite numbers")
            self.pos[i], self.rot[i] = p, rotation_from_quaternion(quaternion)
            self._posed = None

    def placed(self) -> tuple[F64, F64]:
        """Box centres (n, 3) and corners (n, 8, 3) in `map`, computed once per pose update
        (a tick's LiDAR, radar and cameras all need them), read-only."""
        if self._posed is None:
            centre = self.pos + np.einsum("nij,nj->ni", self.rot, self._centre_b)
            local = np.where(CORNER_BITS[None], self._hi[:, None, :], self._lo[:, None, :])
            corners = np.einsum("nij,nkj->nki", self.rot, local) + self.pos[:, None, :]
            centre.flags.writeable = corners.flags.writeable = False
            self._posed = centre, corners
        return self._posed

    def outlines(self, rows: NDArray[np.intp]) -> list[tuple[NDArray[np.intp], F64]]:
        """For each kind of shape among the bodies `rows`: which of them (positions in
        `rows`) and their map-frame points (k, V, 3) whose projection bounds theirs (a box's
        8 corners, a shape's outline)."""
        model = np.take(self._shape, rows)
        groups = []
        for m in np.unique(model).tolist():  # per model, never per body
            sel = np.flatnonzero(model == m)
            bodies = np.take(rows, sel)
            if m < 0:
                points = np.take(self.placed()[1], bodies, axis=0)
            else:
                assert self._shapes is not None
                local, rot = self._shapes.outlines[m], np.take(self.rot, bodies, axis=0)
                points = np.einsum("kij,vj->kvi", rot, local) + self.pos[bodies, None, :]
            groups.append((sel, points))
        return groups

    @property
    def instances(self) -> NDArray[np.int32]:
        return self._inst

    def cones(self, origin: F64, max_range: float) -> Cones:
        """The posed bodies within `max_range` of `origin` and, for each, the cone from the
        origin that holds its box (cull.corner_cone); the last answer is kept for the same
        poses, origin and range (a radar's cast, then its fill: radar_fill.py)."""
        placed, key = self.placed(), (origin.tobytes(), max_range)  # placed: new each update
        last = self._last_cones
        if last is not None and last[0] is placed and last[1] == key:
            return last[2]
        keep = self._in_range(origin, origin, max_range)
        oc = placed[0][keep] - origin
        dist = np.linalg.norm(oc, axis=1)
        cones = Cones(keep, oc, dist, corner_cone(placed[1][keep] - origin, oc, dist))
        self._last_cones = (placed, key, cones)
        return cones

    def _in_range(self, lo: F64, hi: F64, max_range: float) -> NDArray[np.intp]:
        """Posed bodies whose bounding sphere comes within max_range of the box lo..hi."""
        centre = self.placed()[0]
        gap = np.linalg.norm(np.maximum(np.maximum(lo - centre, centre - hi), 0.0), axis=1)
        return np.flatnonzero(np.isfinite(self.pos[:, 0]) & (gap <= max_range + self.radius))

    def _candidates(self, o: F64, d: F64, max_range: float) -> Pairs:
        """(ray, body) pairs whose ray may meet the body's box (services/sensors/cull.py)."""
        if o.strides[0] == 0:  # a LiDAR, a radar: cones from one point; in range: culled
            cone = self.cones(o[0], max_range)
            if cone.body.size == 0:
                return np.empty(0, np.intp), np.empty(0, np.intp)
            ray_i, k = cone_pairs(d, cone.axis, cone.dist, cone.cos_half)
            return ray_i, cone.body[k]
        keep = self._in_range(o.min(axis=0), o.max(axis=0), max_range)
        centre = self.placed()[0]
        ray_i, k = sphere_pairs(o, d, centre[keep], self.radius[keep], max_range)
        return ray_i, keep[k]

    def cast(
        self,
        o: F64,
        d: F64,
        max_range: float,
        near: Nearest,
        pairs: Pairs | None = None,
        *,
        silhouettes: bool = False,
    ) -> NDArray[np.intp] | None:
        """Bodies nearer than the hit so far take the ray: the box test for every pair, the
        shape's own scene for pairs entering a shaped body's box. With `silhouettes`, also
        counts per body the rays that meet it above the calm waterline (z > 0), whatever is
        in front of it (then pairs behind the terrain are cast too)."""
        rng, normal, cls, inst = near.rng, near.normal, near.cls, near.inst
        ray_i, body_i = self._candidates(o, d, max_range) if pairs is None else pairs
        seen = np.zeros(len(self.bodies), np.intp) if silhouettes else None
        if ray_i.size == 0:
            return seen
        take = np.take  # not fancy indexing: take is several times faster on (P, 3) rows
        rot = take(self.rot, body_i, axis=0)  # (P, 3, 3) body -> map
        rel = rows_of(o, ray_i) - take(self.pos, body_i, axis=0)
        ob = np.einsum("pji,pj->pi", rot, rel)  # R^T (o - p)
        db = np.einsum("pji,pj->pi", rot, take(d, ray_i, axis=0))
        t, face_b = slab(ob, db, take(self._lo, body_i, axis=0), take(self._hi, body_i, axis=0))
        before = take(rng, ray_i)
        self._cast_shapes(body_i, ob, db, t, face_b, limit=None if silhouettes else before)
        if seen is not None:
            hit = np.flatnonzero(t <= max_range)  # misses are inf: inf x 0 would warn
            rays = take(ray_i, hit)
            z = take(o[:, 2], rays) + take(t, hit) * take(d[:, 2], rays)
            seen += np.bincount(take(body_i, hit)[z > 0.0], minlength=seen.size)
        ok = np.flatnonzero((t <= max_range) & (t < before))
        ray_i, body_i, t = take(ray_i, ok), take(body_i, ok), take(t, ok)
        face = np.einsum("pij,pj->pi", take(rot, ok, axis=0), take(face_b, ok, axis=0))
        order = np.lexsort((-t, ray_i))  # per ray, nearest last: fancy assignment keeps it
        ray_i, body_i, t, face = ray_i[order], body_i[order], t[order], face[order]
        rng[ray_i], normal[ray_i] = t, face
        cls[ray_i], inst[ray_i] = take(self._cls, body_i), take(self._inst, body_i)
        return seen

    def _cast_shapes(
        self, body_i: NDArray[np.intp], ob: F64, db: F64, t: F64, face: F64, *, limit: F64 | None
    ) -> None:
        """Where a pair enters a shaped body's box (before `limit`, the nearest hit so far,
        when given), its box hit `t` and `face` become the shape's, in place (inf: a miss)."""
        if self._shapes is None:
            return
        live = np.isfinite(t) if limit is None else t < limit
        pairs = np.flatnonzero(live & (np.take(self._shape, body_i) >= 0))
        if pairs.size == 0:
            return
        model = np.take(self._shape, np.take(body_i, pairs))
        ob_p, db_p = np.take(ob, pairs, axis=0), np.take(db, pairs, axis=0)
        t[pairs], face[pairs] = self._shapes.cast(model, ob_p, db_p, np.take(t, pairs))


def _shapes_of(
    bodies: Sequence[Body], lo: F64, hi: F64
) -> tuple[NDArray[np.intp], ShapeCaster | None]:
    """Each body's shape as an index into one ShapeCaster (-1: its box is its shape), each
    distinct shape once, in order of first appearance; a shape must lie inside its box."""
    meshes: dict[int, ShapeMesh] = {}
    for b in bodies:  # once per run
        if b.shape is not None:
            meshes.setdefault(id(b.shape), b.shape)
    index = {key: i for i, key in enumerate(meshes)}
    shape = np.array([index.get(id(b.shape), -1) for b in bodies], dtype=np.intp)
    for i, b in enumerate(bodies):
        if b.shape is not None and not (
            (lo[i] <= b.shape.lo).all() and (hi[i] >= b.shape.hi).all()
        ):
            raise SceneError(f"body {b.id!r}: its shape does not lie inside its box lo..hi")
    return shape, (ShapeCaster(list(meshes.values())) if meshes else None)
