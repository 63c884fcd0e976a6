"""The slab test: where rays enter axis-aligned boxes, vectorised over (ray, box) pairs.

The sensors' scene casts the pairs that pass its cull in each body's own frame, where the
body is the box `lo`..`hi` (services/sensors/scene.py).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

F64 = NDArray[np.float64]


def slab(ob: F64, db: F64, lo: F64, hi: F64) -> tuple[F64, F64]:
    """Entry distance of rays (body frame) into boxes lo..hi (inf if missed or behind), and
    the outward normal of the entry face (body frame). A ray starting inside hits at 0.
    Worked per axis on (3, P) copies: reductions over a trailing axis of 3 are slow."""
    obt, dbt = ob.T.copy(), db.T.copy()
    with np.errstate(divide="ignore", invalid="ignore"):
        inv = 1.0 / dbt
        t1, t2 = (lo.T - obt) * inv, (hi.T - obt) * inv
    t1[np.isnan(t1)] = -np.inf  # parallel ray on a face plane: not limiting
    t2[np.isnan(t2)] = np.inf
    near, far = np.minimum(t1, t2), np.maximum(t1, t2)
    axis = (near[1] > near[0]).astype(np.intp)  # the first axis of the largest entry
    t_in = np.maximum(near[0], near[1])
    axis[near[2] > t_in] = 2
    t_in = np.maximum(t_in, near[2])
    t_out = np.minimum(np.minimum(far[0], far[1]), far[2])
    hit = (t_in <= t_out) & (t_out >= 0.0)
    t = np.where(hit, np.maximum(t_in, 0.0), np.inf)
    face = np.zeros_like(ob)
    rows = np.arange(ob.shape[0])
    face[rows, axis] = -np.sign(dbt[axis, rows])
    return t, face
