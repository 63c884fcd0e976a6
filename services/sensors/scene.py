"""The ray-casting world shared by LiDAR, radar and cameras: terrain, moving bodies, water.

Three kinds of geometry, each with the cheapest exact test for it:
- Terrain: static, so it is one open3d `RaycastingScene` (Embree) built ONCE per run from
  `Terrain.mesh()`; building costs ~0.27 s for 0.5 M triangles, a cast ~7 M rays/s.
- Bodies (vessels, buoys): each its model's shape (two hulls and a deck, a V-hull and a
  cabin, a mesh file), or its hull box for a model without one, culled as its box
  (services/sensors/bodies.py). Moving them must not rebuild any scene: a conservative cull
  leaves a few (ray, body) pairs, those get the slab test against the box in the body's
  own frame (exact for a box), and the pairs that enter a shaped body's box are cast, in
  that frame, into its model's own Embree scene, built once (services/sensors/shapes.py).
  100 boats cost a fraction of
  a millisecond per 32 x 512 scan (benchmarks/sensors.py).
- Water: the same surface as physics, z = WaveField.height(x, y, t). Calm water is the plane
  z = 0. With waves, a cast samples the surface once on a grid over its rays' footprint
  (services/sensors/wave_cast.py: heights and gradients of every node from one matmul,
  cells sized so that the bilinear surface is within 7 mm of the true one) and a compiled
  loop finds each ray's first crossing of it (wave_kernel.py, wave_pass.py); casts of a
  few rays and rays leaving the grid take the exact march of water.py (compiled too,
  wave_march.py). A 32 x 512 LiDAR
  scan in the medium swell: ~1 ms more than on calm water, a 640 x 480 camera ~11 ms.

The nearest hit of the three wins. All work is vectorised over rays (or compiled, for the
wave surface); no Python loop runs per ray, and loops over bodies run over no more than a
handful of refinement steps.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from catabot.bus.messages import CLASS_NONE, CLASS_TERRAIN, CLASS_WATER
from catabot.world.terrain import Terrain
from catabot.world.waves import WaveField
from services.sensors.bodies import Bodies, Body, Pairs, SceneError
from services.sensors.cull import Cones
from services.sensors.terrain_cast import TerrainCaster
from services.sensors.water import calm_hits
from services.sensors.wave_cast import WaveCaster

F32 = NDArray[np.float32]
F64 = NDArray[np.float64]
UP = np.array([0.0, 0.0, 1.0], dtype=np.float32)
__all__ = ["Body", "Cones", "Hits", "Scene", "SceneError"]  # Body, its error: bodies.py


@dataclass
class Hits:
    """The first hit of each ray; inf range, zero normal and CLASS_NONE where none."""

    range: F32  # (N,) metres along the (unit) ray direction
    normal: F32  # (N, 3) world-frame unit normals
    cls: NDArray[np.uint8]  # (N,)
    instance: NDArray[np.int32]  # (N,)
    silhouette: NDArray[np.intp] | None = None  # per body: see Scene.cast(silhouettes=)


@dataclass(frozen=True)
class _Nearest:
    """The nearest hit so far of each ray, updated in place by each kind of surface."""

    rng: F64
    normal: F32
    cls: NDArray[np.uint8]
    inst: NDArray[np.int32]


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
        self._water = WaveCaster(waves)
        self._bodies = Bodies(bodies)  # boxes, shapes, poses (bodies.py)
        self.bodies = self._bodies.bodies
        self.time_s = 0.0

    @property
    def water_plan(self) -> str:
        """What the last cast did with the water ("grid nu x nv, k rays exact", "exact";
        empty for calm water): for benchmarks and tests."""
        return self._water.last_plan

    def set_waves(self, waves: WaveField) -> None:
        """A run-time change of the sea (`catabot set waves`): the surface rays hit."""
        self._waves = waves
        self._water = WaveCaster(waves)

    def update(
        self, poses: Mapping[str, tuple[Sequence[float], Sequence[float]]], time_s: float
    ) -> None:
        """Set the pose (position xyz, quaternion xyzw in `map`) of the named bodies and the
        time of the wave surface; bodies not named keep their last pose. Every body at once
        (called each tick with ~100 poses: one by one cost ~0.6 ms); a bad pose is named by
        the one-by-one path."""
        if poses:
            self._bodies.place(poses)
        self.time_s = float(time_s)

    def update_arrays(
        self, ids: Sequence[str], position: np.ndarray, orientation: np.ndarray, time_s: float
    ) -> None:
        """Every body of a `BodyStates` batch at once, row i being `ids[i]`: the per-tick
        path, with no per-body Python objects (rows are mapped once per id list); a bad
        row goes through `update`, which names it."""
        if not self._bodies.place_arrays(ids, position, orientation):
            self.update(
                dict(zip(ids, zip(position, orientation, strict=False), strict=False)), time_s
            )
            return
        self.time_s = float(time_s)

    @property
    def instances(self) -> NDArray[np.int32]:
        """Every body's instance id, in `bodies` order (read-only)."""
        return self._bodies.instances

    def corners(self) -> F64:
        """(n, 8, 3) map-frame corners of every body's box, in `bodies` order (NaN where not
        yet posed): a camera projects them to find the pixels that may see each body."""
        return self._bodies.placed()[1]

    def outlines(self, rows: NDArray[np.intp]) -> list[tuple[NDArray[np.intp], F64]]:
        """Per kind of shape among the bodies `rows`: which of them (positions in `rows`)
        and map-frame points (k, V, 3) whose projection bounds theirs (a camera's 2D box of
        the whole body: a box's 8 corners, a shape's outline)."""
        return self._bodies.outlines(rows)

    def cast(
        self,
        origins: np.ndarray,
        directions: np.ndarray,
        max_range: float,
        pairs: tuple[NDArray[np.intp], NDArray[np.intp]] | None = None,
        *,
        silhouettes: bool = False,
        normals: bool = True,
    ) -> Hits:
        """First hit of each ray (origins (N,3) or (3,), directions (N,3), normalised here)
        within `max_range` metres. `pairs` (ray, body index) replaces the body cull when the
        caller knows which rays can meet which body (a camera projects each box into its
        image); it must hold every pair that can hit. `silhouettes`: also count, per body,
        the rays that meet its shape above the calm waterline whatever is in front of it
        (a camera's measure of how much of a body an unobstructed view would show).
        `normals=False`: a caller that ignores normals (a LiDAR) spares the wave surface's
        (≈20 ns a hit); its water hits then carry the calm one, straight up."""
        o, d = _rays(origins, directions)
        rng, normal, hit = self._terrain.cast(o, d, max_range)
        cls = np.where(hit, np.uint8(CLASS_TERRAIN), np.uint8(CLASS_NONE))
        near = _Nearest(rng, normal, cls, np.zeros(d.shape[0], dtype=np.int32))
        seen = self._cast_bodies(o, d, max_range, near, pairs, silhouettes=silhouettes)
        self._cast_water(o, d, max_range, near, normals)
        return Hits(near.rng.astype(np.float32), near.normal, near.cls, near.inst, seen)

    def _cast_water(
        self, o: F64, d: F64, max_range: float, near: _Nearest, normals: bool = True
    ) -> None:
        """Rays that meet the water before anything else get the water's hit."""
        rng, normal, cls, inst = near.rng, near.normal, near.cls, near.inst
        if self._waves.is_calm or self._water.amplitude <= 0.0:
            t = calm_hits(o, d, max_range)
            closer = t < rng
            np.copyto(rng, t, where=closer)
            for axis in range(3):  # per column: an (N, 3) masked copy is ~6x slower
                np.copyto(normal[:, axis], UP[axis], where=closer)
            np.copyto(cls, np.uint8(CLASS_WATER), where=closer)
            np.copyto(inst, 0, where=closer)
            return
        self._water.cast(o, d, max_range, near, self.time_s, normals=normals)

    def _cast_bodies(
        self,
        o: F64,
        d: F64,
        max_range: float,
        near: _Nearest,
        pairs: Pairs | None = None,
        *,
        silhouettes: bool = False,
    ) -> NDArray[np.intp] | None:
        return self._bodies.cast(o, d, max_range, near, pairs, silhouettes=silhouettes)

    def cones(self, origin: F64, max_range: float) -> Cones:
        """The posed bodies within `max_range` of `origin` and, for each, the cone from the
        origin that holds its box: a sensor with a fixed grid of rays (a LiDAR) turns these
        into (ray, body) pairs for `cast` without testing every ray (cull.grid_pairs)."""
        return self._bodies.cones(origin, max_range)


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
