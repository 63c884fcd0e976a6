"""Vessel shapes in the ray cast: one Embree scene per model, rays cast in the body's frame.

A shape (catabot/world/shapes.py) never changes in its body's frame, so each model's mesh
goes into an open3d `RaycastingScene` once per run and a moving body is handled by moving
the rays instead: the scene's cull and slab test against the shape's bounding box leave the
(ray, body) pairs that enter the box, those are turned into the body's frame (where the
box test already put them), and all pairs of one model go to that model's scene in ONE
`cast_rays` call (a loop over the distinct models, never over rays or bodies). Posing 100
boats therefore rebuilds nothing, and the rays Embree sees are only those that reach a box.

Each ray starts a little before its box entry (`LEAD_M`): the mesh lies inside the box, so
no hit is skipped, and the ray's coordinates stay within metres of the mesh, where float32
is exact to micrometres (a ray from 100 m away would carry 8 um of rounding). Normals are
turned to face the ray, so a mesh wound either way shades and reflects alike.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

from catabot.world.shapes import ShapeMesh

F64 = NDArray[np.float64]
F32 = NDArray[np.float32]
LEAD_M = 0.01  # rays start this far before their box entry (coordinates stay small)
OUTLINE_MAX = 64  # more mesh vertices than this: its convex hull's stand in for the outline


class ShapeCaster:
    """The Embree scenes of every distinct shape, built once, and the casts into them."""

    def __init__(self, meshes: Sequence[ShapeMesh]) -> None:
        self.meshes = list(meshes)
        self._scenes = [_scene(m) for m in self.meshes]
        self.outlines = [_outline(m) for m in self.meshes]

    def cast(self, model: NDArray[np.intp], ob: F64, db: F64, t_box: F64) -> tuple[F64, F64]:
        """First hit of each body-frame ray (origin `ob`, unit direction `db`) on the shape
        `model` (index into `meshes`), given where it enters that shape's box: distance from
        `ob` (inf: a miss) and the body-frame unit normal facing the ray (zero: a miss).
        The rays are sorted by model once, so each model's are one slice and one call."""
        order = np.argsort(model, kind="stable")
        m_sorted = np.take(model, order)
        dirs = np.take(db, order, axis=0)
        start = np.maximum(np.take(t_box, order) - LEAD_M, 0.0)
        rays = np.empty((order.size, 6), dtype=np.float32)
        rays[:, :3] = np.take(ob, order, axis=0) + start[:, None] * dirs
        rays[:, 3:] = dirs
        cuts = np.flatnonzero(np.diff(m_sorted)) + 1
        t_hit = np.empty(order.size, dtype=np.float32)
        normal = np.empty((order.size, 3), dtype=np.float32)
        for lo, hi in zip([0, *cuts.tolist()], [*cuts.tolist(), order.size], strict=True):
            self._cast(int(m_sorted[lo]), rays[lo:hi], t_hit[lo:hi], normal[lo:hi])
        back = np.empty_like(order)
        back[order] = np.arange(order.size)
        t = np.take(start + t_hit.astype(np.float64), back)  # a miss: inf
        n = np.take(normal, back, axis=0).astype(np.float64)
        n[np.einsum("pj,pj->p", n, db) > 0.0] *= -1.0  # face the ray
        return t, n

    def _cast(self, m: int, rays: F32, t_hit: F32, normal: F32) -> None:
        """Model m's rays into its scene; Embree's float32 results into the given slices."""
        import open3d as o3d  # loaded only by a process that casts against shapes

        out = self._scenes[m].cast_rays(o3d.core.Tensor.from_numpy(rays))
        t_hit[:] = out["t_hit"].numpy()
        normal[:] = out["primitive_normals"].numpy()


def _scene(mesh: ShapeMesh) -> Any:
    import open3d as o3d

    scene = o3d.t.geometry.RaycastingScene()
    scene.add_triangles(
        o3d.core.Tensor.from_numpy(np.ascontiguousarray(mesh.vertices, dtype=np.float32)),
        o3d.core.Tensor.from_numpy(np.ascontiguousarray(mesh.triangles, dtype=np.uint32)),
    )
    return scene


def _outline(mesh: ShapeMesh) -> F64:
    """Points whose projection bounds the mesh's in any pinhole view (a camera's 2D box of
    the whole body): the vertices that triangles use, or their convex hull's if many."""
    points = mesh.vertices[np.unique(mesh.triangles)]
    if points.shape[0] <= OUTLINE_MAX:
        return points
    import open3d as o3d

    cloud = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(points))
    try:
        _, kept = cloud.compute_convex_hull()
    except RuntimeError:  # flat or degenerate: qhull refuses; every vertex still bounds it
        return points
    return points[np.unique(np.asarray(kept))]
