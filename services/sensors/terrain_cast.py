"""Rays against the terrain mesh in Embree (open3d's `RaycastingScene`), built once a run."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from catabot.world.terrain import Terrain

F64 = NDArray[np.float64]
F32 = NDArray[np.float32]


class TerrainCaster:
    """The terrain's Embree scene and the float32 ray buffers handed to it."""

    def __init__(self, terrain: Terrain | None) -> None:
        self._scene = terrain.raycasting_scene() if terrain is not None else None
        self._buffers: dict[int, F32] = {}

    def cast(self, o: F64, d: F64, max_range: float) -> tuple[F64, F32, NDArray[np.bool_]]:
        """Range (inf: none within max_range), float32 normal (zero: none) and whether the
        ray hit, for each ray: Embree's own float32 outputs, copied as little as possible."""
        n = d.shape[0]
        if self._scene is None:
            return np.full(n, np.inf), np.zeros((n, 3), np.float32), np.zeros(n, bool)
        import open3d as o3d

        rays = self._ray_buffer(n)
        rays[:, :3] = o
        rays[:, 3:] = d  # rounded to float32 as astype would
        out = self._scene.cast_rays(o3d.core.Tensor.from_numpy(rays))
        t32 = out["t_hit"].numpy()
        normal: F32 = out["primitive_normals"].numpy()  # Embree gives zero on a miss
        far = t32 > max_range  # misses (inf) too
        rng = t32.astype(np.float64)
        beyond = np.flatnonzero(far & (t32 < np.inf))  # hits past max_range: none of it
        rng[beyond], normal[beyond] = np.inf, 0.0
        return rng, normal, ~far

    def _ray_buffer(self, n: int) -> F32:
        """The (n, 6) float32 rays handed to Embree, reused across casts of the same size
        (a fresh 7 MB array per camera frame costs ~1 ms of page faults). One cast at a
        time: a caster is not shared between threads."""
        buf = self._buffers.get(n)
        if buf is None:
            buf = self._buffers[n] = np.empty((n, 6), dtype=np.float32)
            if len(self._buffers) > 8:  # sizes vary (radar sectors): keep a few
                self._buffers.pop(next(iter(self._buffers)))
        return buf
