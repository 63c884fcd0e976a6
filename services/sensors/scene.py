"""The ray-casting world shared by LiDAR, radar and cameras: terrain, moving bodies, water.

Three kinds of geometry, each with the cheapest exact test for it:
- Terrain: static, so it is one open3d `RaycastingScene` (Embree) built ONCE per run from
  `Terrain.mesh()`; building costs ~0.27 s for 0.5 M triangles, a cast ~7 M rays/s.
- Bodies (vessels, buoys): moving boxes (the union AABB of the model's hulls, in the body
  frame). Moving them must not rebuild the terrain scene, so they are tested analytically:
  bodies out of range of every ray origin are dropped, a cheap conservative pre-test leaves
  a few (ray, body) pairs (services/sensors/cull.py: cones from a shared origin, tested per
  bundle of rays; a camera or LiDAR passes its own pairs, from its pixel or beam grid), and
  only those pairs get the slab test in the body's own frame. 100 boats cost well under
  a millisecond per 32 x 512 scan (benchmarks/sensors.py).
- Water: the same surface as physics, z = WaveField.height(x, y, t). Calm water is the plane
  z = 0. With waves, each downward ray is bracketed between z = +A and z = -A (A = the sum of
  the component amplitudes bounds |eta|), marched in a few samples to find the FIRST sign
  change of f(t) = z(t) - eta(x(t), y(t)), then refined by Illinois false position: the hit is
  on the surface within a millimetre. Its cost is (downward rays x ~7 evaluations x
  components) float32 cosines, ~8 ms per 32 x 512 LiDAR scan in harbour chop (water.py).

The nearest hit of the three wins. All work is vectorised over rays; no Python loop runs per
ray, and loops over bodies run over no more than a handful of refinement steps.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from catabot.bus.messages import CLASS_NONE, CLASS_TERRAIN, CLASS_WATER
from catabot.world.terrain import Terrain
from catabot.world.waves import WaveField
from services.sensors.common import (
    SensorError,
    rotation_from_quaternion,
    rotations_from_quaternions,
    rows_of,
)
from services.sensors.cull import cone_pairs, sphere_pairs
from services.sensors.slab import slab
from services.sensors.terrain_cast import TerrainCaster
from services.sensors.water import calm_hits, wave_hits

F32 = NDArray[np.float32]
F64 = NDArray[np.float64]
Vec3 = tuple[float, float, float]
UP = np.array([0.0, 0.0, 1.0], dtype=np.float32)
CORNER_BITS = np.array([[i >> 2 & 1, i >> 1 & 1, i & 1] for i in range(8)], dtype=bool)
"""Corner i of a box takes hi on axis x, y, z where bit 2, 1, 0 of i is set."""


class SceneError(SensorError):
    """Rays or poses the scene cannot use (wrong shapes, non-finite values, unknown body)."""


@dataclass(frozen=True)
class Body:
    """A moving box-shaped body: hull bounds `lo`..`hi` in its body frame (FLU)."""

    id: str
    cls: int
    instance: int
    lo: Vec3
    hi: Vec3


@dataclass
class Hits:
    """The first hit of each ray; inf range, zero normal and CLASS_NONE where none."""

    range: F32  # (N,) metres along the (unit) ray direction
    normal: F32  # (N, 3) world-frame unit normals
    cls: NDArray[np.uint8]  # (N,)
    instance: NDArray[np.int32]  # (N,)


@dataclass(frozen=True)
class _Nearest:
    """The nearest hit so far of each ray, updated in place by each kind of surface."""

    rng: F64
    normal: F32
    cls: NDArray[np.uint8]
    inst: NDArray[np.int32]


@dataclass
class Cones:
    """Per body in range (`body`: index in Scene.bodies): the vector from the origin to its
    box centre (`axis`, of length `dist`) and the cos of the half-angle of the cone about it
    that holds the box (-1: every direction)."""

    body: NDArray[np.intp]
    axis: F64
    dist: F64
    cos_half: F64


class Scene:
    """Terrain (built once), bodies (posed by `update`) and the wave surface at `time_s`."""

    def __init__(
        self,
        *,
        terrain: Terrain | None,
        waves: WaveField,
        bodies: Sequence[Body],
        rain_rate_mm_h: float = 0.0,
    ) -> None:
        self.rain_rate_mm_h = float(rain_rate_mm_h)  # the rain in force (LiDAR's rain model)
        self._terrain = TerrainCaster(terrain)
        self._waves = waves
        self._amplitude = float(np.sum(waves.amplitudes_m))
        self.bodies = list(bodies)
        self._index = {b.id: i for i, b in enumerate(self.bodies)}
        self._rows_ids: tuple[str, ...] = ()  # update_arrays' id list and its scene rows
        self._rows = np.empty(0, np.intp)
        if len(self._index) != len(self.bodies):
            raise SceneError("body ids must be unique")
        lo = np.array([b.lo for b in self.bodies], dtype=np.float64).reshape(-1, 3)
        hi = np.array([b.hi for b in self.bodies], dtype=np.float64).reshape(-1, 3)
        self._lo, self._hi = lo, hi
        self._centre_b = (lo + hi) / 2  # box centre in the body frame
        self._radius = np.linalg.norm(hi - lo, axis=1) / 2
        self._cls = np.array([b.cls for b in self.bodies], dtype=np.uint8)
        self._inst = np.array([b.instance for b in self.bodies], dtype=np.int32)
        n = len(self.bodies)
        self._pos = np.full((n, 3), np.nan)  # unposed bodies are not in the scene
        self._rot = np.tile(np.eye(3), (n, 1, 1))
        self.time_s = 0.0
        self._posed: tuple[F64, F64] | None = None  # (centres, corners) of the poses now

    def set_waves(self, waves: WaveField) -> None:
        """A run-time change of the sea (`catabot set waves`): the surface rays hit."""
        self._waves = waves
        self._amplitude = float(np.sum(waves.amplitudes_m))

    def update(
        self, poses: Mapping[str, tuple[Sequence[float], Sequence[float]]], time_s: float
    ) -> None:
        """Set the pose (position xyz, quaternion xyzw in `map`) of the named bodies and the
        time of the wave surface; bodies not named keep their last pose. Every body at once
        (called each tick with ~100 poses: one by one cost ~0.6 ms); a bad pose is named by
        the one-by-one path."""
        if poses:
            self._set_poses(poses)
        self.time_s = float(time_s)

    def update_arrays(
        self, ids: Sequence[str], position: np.ndarray, orientation: np.ndarray, time_s: float
    ) -> None:
        """Every body of a `BodyStates` batch at once, row i being `ids[i]`: the per-tick
        path, with no per-body Python objects (rows are mapped once per id list); a bad
        row goes through `update`, which names it."""
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
            self.update(
                dict(zip(ids, zip(position, orientation, strict=False), strict=False)), time_s
            )
            return
        self._pos[rows], self._rot[rows] = position, rot
        self._posed = None
        self.time_s = float(time_s)

    def _set_poses(self, poses: Mapping[str, tuple[Sequence[float], Sequence[float]]]) -> None:
        rows = [self._index.get(body_id, -1) for body_id in poses]
        try:
            pos = np.array([p for p, _ in poses.values()], dtype=np.float64)
            quat = np.array([q for _, q in poses.values()], dtype=np.float64)
        except (ValueError, TypeError):  # ragged: some pose has the wrong length
            pos = quat = np.empty(0)
        n = len(rows)
        rot = rotations_from_quaternions(quat) if quat.shape == (n, 4) else None
        if min(rows) < 0 or pos.shape != (n, 3) or not np.isfinite(pos).all() or rot is None:
            self._update_one_by_one(poses)
            return
        self._pos[rows], self._rot[rows] = pos, rot
        self._posed = None

    def _update_one_by_one(
        self, poses: Mapping[str, tuple[Sequence[float], Sequence[float]]]
    ) -> None:
        for body_id, (position, quaternion) in poses.items():
            i = self._index.get(body_id)
            if i is None:
                raise SceneError(f"unknown body {body_id!r} (known: {sorted(self._index)})")
            p = np.asarray(position, dtype=np.float64)
            if p.shape != (3,) or not np.isfinite(p).all():
                raise SceneError(f"body {body_id!r}: position must be 3 finite numbers")
            self._pos[i], self._rot[i] = p, rotation_from_quaternion(quaternion)
            self._posed = None

    def corners(self) -> F64:
        """(n, 8, 3) map-frame corners of every body's box, in `bodies` order (NaN where not
        yet posed): a camera projects them to tell a truncated or occluded 2D box."""
        return self._placed()[1]

    def _placed(self) -> tuple[F64, F64]:
        """Box centres (n, 3) and corners (n, 8, 3) in `map`, computed once per pose update
        (a tick's LiDAR, radar and cameras all need them), read-only."""
        if self._posed is None:
            centre = self._pos + np.einsum("nij,nj->ni", self._rot, self._centre_b)
            local = np.where(CORNER_BITS[None], self._hi[:, None, :], self._lo[:, None, :])
            corners = np.einsum("nij,nkj->nki", self._rot, local) + self._pos[:, None, :]
            centre.flags.writeable = corners.flags.writeable = False
            self._posed = centre, corners
        return self._posed

    def cast(
        self,
        origins: np.ndarray,
        directions: np.ndarray,
        max_range: float,
        pairs: tuple[NDArray[np.intp], NDArray[np.intp]] | None = None,
    ) -> Hits:
        """First hit of each ray (origins (N,3) or (3,), directions (N,3), normalised here)
        within `max_range` metres. `pairs` (ray, body index) replaces the body cull when the
        caller knows which rays can meet which body (a camera projects each box into its
        image); it must hold every pair that can hit."""
        o, d = _rays(origins, directions)
        rng, normal, hit = self._terrain.cast(o, d, max_range)
        cls = np.where(hit, np.uint8(CLASS_TERRAIN), np.uint8(CLASS_NONE))
        near = _Nearest(rng, normal, cls, np.zeros(d.shape[0], dtype=np.int32))
        self._cast_bodies(o, d, max_range, near, pairs)
        self._cast_water(o, d, max_range, near)
        return Hits(near.rng.astype(np.float32), near.normal, near.cls, near.inst)

    def _cast_water(self, o: F64, d: F64, max_range: float, near: _Nearest) -> None:
        """Rays that meet the water before anything else get the water's hit."""
        rng, normal, cls, inst = near.rng, near.normal, near.cls, near.inst
        if self._waves.is_calm or self._amplitude <= 0.0:
            t = calm_hits(o, d, max_range)
            closer = t < rng
            np.copyto(rng, t, where=closer)
            for axis in range(3):  # per column: an (N, 3) masked copy is ~6x slower
                np.copyto(normal[:, axis], UP[axis], where=closer)
            np.copyto(cls, np.uint8(CLASS_WATER), where=closer)
            np.copyto(inst, 0, where=closer)
            return
        limit = np.minimum(rng, max_range)
        rows, t, nw = wave_hits(self._waves, self._amplitude, o, d, limit, self.time_s)
        closer = t < rng[rows]
        rows = rows[closer]
        rng[rows], normal[rows], cls[rows], inst[rows] = t[closer], nw[closer], CLASS_WATER, 0

    def _cast_bodies(
        self,
        o: F64,
        d: F64,
        max_range: float,
        near: _Nearest,
        pairs: tuple[NDArray[np.intp], NDArray[np.intp]] | None = None,
    ) -> None:
        rng, normal, cls, inst = near.rng, near.normal, near.cls, near.inst
        ray_i, body_i = self._candidates(o, d, max_range) if pairs is None else pairs
        if ray_i.size == 0:
            return
        take = np.take  # not fancy indexing: take is several times faster on (P, 3) rows
        rot = take(self._rot, body_i, axis=0)  # (P, 3, 3) body -> map
        rel = rows_of(o, ray_i) - take(self._pos, body_i, axis=0)
        ob = np.einsum("pji,pj->pi", rot, rel)  # R^T (o - p)
        db = np.einsum("pji,pj->pi", rot, take(d, ray_i, axis=0))
        t, face_b = slab(ob, db, take(self._lo, body_i, axis=0), take(self._hi, body_i, axis=0))
        ok = np.flatnonzero((t <= max_range) & (t < take(rng, ray_i)))
        ray_i, body_i, t = take(ray_i, ok), take(body_i, ok), take(t, ok)
        face = np.einsum("pij,pj->pi", take(rot, ok, axis=0), take(face_b, ok, axis=0))
        order = np.lexsort((-t, ray_i))  # per ray, nearest last: fancy assignment keeps it
        ray_i, body_i, t, face = ray_i[order], body_i[order], t[order], face[order]
        rng[ray_i], normal[ray_i] = t, face
        cls[ray_i], inst[ray_i] = take(self._cls, body_i), take(self._inst, body_i)

    def cones(self, origin: F64, max_range: float) -> Cones:
        """The posed bodies within `max_range` of `origin` and, for each, the cone from the
        origin that holds its box: a sensor with a fixed grid of rays (a LiDAR) turns these
        into (ray, body) pairs for `cast` without testing every ray (cull.grid_pairs)."""
        keep = self._in_range(origin, origin, max_range)
        oc = self._placed()[0][keep] - origin
        dist = np.linalg.norm(oc, axis=1)
        return Cones(keep, oc, dist, self._corner_cone(keep, origin, oc, dist))

    def _in_range(self, lo: F64, hi: F64, max_range: float) -> NDArray[np.intp]:
        """Posed bodies whose bounding sphere comes within max_range of the box lo..hi."""
        centre = self._placed()[0]
        gap = np.linalg.norm(np.maximum(np.maximum(lo - centre, centre - hi), 0.0), axis=1)
        return np.flatnonzero(np.isfinite(self._pos[:, 0]) & (gap <= max_range + self._radius))

    def _candidates(
        self, o: F64, d: F64, max_range: float
    ) -> tuple[NDArray[np.intp], NDArray[np.intp]]:
        """(ray, body) pairs whose ray may meet the body's box (services/sensors/cull.py)."""
        if o.strides[0] == 0:  # a LiDAR, a radar: cones from one point; in range: culled
            cone = self.cones(o[0], max_range)
            if cone.body.size == 0:
                return np.empty(0, np.intp), np.empty(0, np.intp)
            ray_i, k = cone_pairs(d, cone.axis, cone.dist, cone.cos_half)
            return ray_i, cone.body[k]
        keep = self._in_range(o.min(axis=0), o.max(axis=0), max_range)
        centre = self._placed()[0]
        ray_i, k = sphere_pairs(o, d, centre[keep], self._radius[keep], max_range)
        return ray_i, keep[k]

    def _corner_cone(self, keep: NDArray[np.intp], origin: F64, oc: F64, dist: F64) -> F64:
        """cos of the half-angle of the cone from `origin` about each body's centre that holds
        its 8 corners, so holds the box (-1: every direction, when that cone is not convex).
        Tighter than the bounding sphere, and still a cull when the origin is inside the
        sphere (a LiDAR above its own hull), where the sphere test passes every ray."""
        rel = self._placed()[1][keep] - origin  # (K, 8, 3)
        cos = np.einsum("kcj,kj->kc", rel, oc) / (
            np.linalg.norm(rel, axis=2) * dist[:, None] + 1e-300
        )
        cos_half = cos.min(axis=1) - 1e-9
        return np.where(cos_half > 0.0, cos_half, -1.0)


def _rays(origins: np.ndarray, directions: np.ndarray) -> tuple[F64, F64]:
    d = np.asarray(directions, dtype=np.float64)
    if d.ndim != 2 or d.shape[1] != 3:
        raise SceneError(f"directions must have shape (N, 3) (got {d.shape})")
    raw = np.asarray(origins, dtype=np.float64)
    o = np.broadcast_to(raw, d.shape)  # one shared origin stays a stride-0 view (cheap cull)
    norm = np.sqrt(np.einsum("ij,ij->i", d, d))  # a NaN or inf anywhere in d shows here too
    if not (np.isfinite(raw).all() and np.isfinite(norm).all() and (norm > 0).all()):
        raise SceneError("rays need finite origins and finite, non-zero directions")
    if d is directions:  # the caller's own array: never scale it in place
        return o, d / norm[:, None]
    d /= norm[:, None]  # a fresh float64 copy made above
    return o, d
