"""Each vessel model's shape as one triangle mesh in its body frame (FLU, metres).

What the ray-casting sensors hit and the viewer draws: the model's `shape` (a mesh file or
primitives, catabot/config/vessel_shape.py), or None for a model without one, which sensors
see as its hull box. Built once per model per process that needs it (the sensors, the
viewer, and the launcher, which reads every mesh file before anything starts so a broken one
is refused like any bad model); physics, traffic and the recorder never build one.

A mesh file is read with open3d (OBJ, STL, glTF), imported only then: a process whose
models are all primitives never loads it. A file open3d cannot read comes back as an empty
mesh with a warning on stdout, so emptiness is the test, and the message names the file.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from catabot.config.vessel import VesselModel, VesselModelError
from catabot.config.vessel_shape import MeshFile
from catabot.world import rotations
from catabot.world.shape_parts import parts_mesh

F64 = NDArray[np.float64]
I32 = NDArray[np.int32]
MAX_TRIANGLES = 2_000_000  # a vessel, not a city: more is a mistake (and memory per process)


class MeshFileError(VesselModelError):
    """A shape's mesh file that cannot be used: unreadable, empty, not finite, too big."""


@dataclass(frozen=True, eq=False)  # compared by identity: it holds arrays
class ShapeMesh:
    """A closed (or not: sensors do not care) triangle mesh in the body frame."""

    vertices: F64  # (V, 3)
    triangles: I32  # (T, 3) indices into vertices

    @property
    def lo(self) -> F64:
        """Body-frame corner of the mesh's axis-aligned box (the sensors' cull uses it)."""
        return np.asarray(self.vertices.min(axis=0))

    @property
    def hi(self) -> F64:
        return np.asarray(self.vertices.max(axis=0))


def vessel_mesh(model: VesselModel, *, source: str) -> ShapeMesh | None:
    """The model's shape as a mesh, None without one; `source` (its name or path) is named
    in a MeshFileError."""
    shape = model.shape
    if shape is None:
        return None
    if shape.parts is not None:
        return ShapeMesh(*parts_mesh(shape.parts, model.hulls))
    assert shape.mesh is not None  # the model validator wants exactly one
    return _placed(_read(shape.mesh.file, source), shape.mesh)


def _read(file: str, source: str) -> ShapeMesh:
    import open3d as o3d  # only for mesh files: primitives need no reader

    def refuse(problem: str) -> MeshFileError:
        return MeshFileError(f"vessel model '{source}': shape.mesh.file {file!r}: {problem}")

    if not Path(file).is_file():
        raise refuse("no such file")
    o3d.utility.set_verbosity_level(o3d.utility.VerbosityLevel.Error)
    try:
        mesh = o3d.io.read_triangle_mesh(Path(file))
    except (RuntimeError, OSError, ValueError) as exc:
        raise refuse(f"cannot read ({exc})") from None
    vertices = np.asarray(mesh.vertices, dtype=np.float64)
    triangles = np.asarray(mesh.triangles, dtype=np.int64)
    if triangles.shape[0] == 0:
        raise refuse("no triangles in it (unreadable, not a mesh, or empty)")
    if triangles.shape[0] > MAX_TRIANGLES:
        raise refuse(f"{triangles.shape[0]} triangles, over {MAX_TRIANGLES}")
    if not np.isfinite(vertices).all():
        raise refuse("vertices that are not finite numbers")
    if triangles.min() < 0 or triangles.max() >= vertices.shape[0]:
        raise refuse("triangles that name missing vertices")
    return ShapeMesh(vertices, triangles.astype(np.int32))


def _placed(mesh: ShapeMesh, where: MeshFile) -> ShapeMesh:
    """The file's vertices in the body frame: R(rpy) (scale * v) + offset."""
    rot = rotations.rpy(*where.rpy_deg)
    vertices = (mesh.vertices * np.asarray(where.scale)) @ rot.T + np.asarray(where.offset_m)
    return ShapeMesh(vertices, mesh.triangles)
