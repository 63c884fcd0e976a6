"""The terrain as the metrics see it: distance to the shore, and whether a hull is aground.

Shore distance: the distance from a vessel's origin to the nearest pixel centre at or above
the water line (elevation >= 0), from an exact Euclidean distance transform of the land mask
computed once (`distance_transform`), read per tick by the terrain's own bilinear lookup
(positions off the map are clamped to its edge, as the terrain itself is).

Grounding: a vessel is aground while any of its hull-bottom probes (catabot.world.hulls, the
points physics pushes off the ground) is below the terrain surface: the test physics applies
a contact force on. Probes are only placed for vessels near water shallower than their keel
plus `SHALLOW_MARGIN_M` (a second distance transform), so open water costs one lookup.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from catabot.world.hulls import model_probes
from catabot.world.rotations import matrices
from catabot.world.terrain import Terrain
from catabot.world.world import Body
from services.recorder.tasks import rowdot

Array = NDArray[np.float64]
SHALLOW_MARGIN_M = 3.0  # heave in waves and roll or pitch lower a keel by less than this


def distance_transform(mask: NDArray[np.bool_]) -> Array:
    """Euclidean distance (in pixels) from every pixel centre to the nearest True pixel centre,
    inf where there is none: exact (Felzenszwalb & Huttenlocher 2012), columns first, then the
    lower envelope of parabolas along each row, vectorised over all rows at once."""
    ny = mask.shape[0]
    index = np.arange(ny, dtype=np.float64)[:, None]
    above = np.maximum.accumulate(np.where(mask, index, -np.inf), axis=0)
    below = np.minimum.accumulate(np.where(mask, index, np.inf)[::-1], axis=0)[::-1]
    column = np.minimum(index - above, below - index)
    return np.sqrt(_row_envelope(column * column))


def _row_envelope(f: Array) -> Array:
    """min over q of (x - q)^2 + f[:, q] for every x, per row (inf entries: no parabola)."""
    m, n = f.shape
    rows, top = np.arange(m), np.full(m, -1)
    apex = np.zeros((m, n), dtype=np.intp)  # the parabolas of the envelope, left to right
    bound = np.full((m, n + 1), np.inf)  # where each takes over from the previous one
    for q in range(n):
        act = np.flatnonzero(np.isfinite(f[:, q]))
        if not len(act):
            continue
        k, fq = top[act], f[act, q]
        while True:
            v = apex[act, np.maximum(k, 0)]
            with np.errstate(divide="ignore", invalid="ignore"):  # k < 0: no parabola yet
                s = ((fq + q * q) - (f[act, v] + v * v)) / (2.0 * (q - v))
            s = np.where(k >= 0, s, -np.inf)
            pop = (k >= 0) & (s <= bound[act, np.maximum(k, 0)])
            if not pop.any():
                break
            k = k - pop
        k = k + 1
        apex[act, k], bound[act, k], bound[act, k + 1] = q, s, np.inf
        top[act] = k
    out = np.full((m, n), np.inf)
    have, j = top >= 0, np.zeros(m, dtype=np.intp)
    for x in range(n):
        while True:
            step = have & (j < top) & (bound[rows, np.minimum(j + 1, n)] < x)
            if not step.any():
                break
            j = j + step
        v = apex[rows, j]
        out[:, x] = np.where(have, (x - v) ** 2 + f[rows, v], np.inf)
    return out


class Seabed:
    """Shore distance and grounding of the scenario vessels (`bodies`, rows 0..S-1)."""

    def __init__(self, terrain: Terrain, bodies: tuple[Body, ...]) -> None:
        self.terrain = terrain
        z, self.mpp = terrain.elevation_m, terrain.metres_per_pixel
        probes = [model_probes(b.model) for b in bodies]
        width = max(len(p) for p in probes)
        self.probes = np.zeros((len(bodies), width, 3))
        for i, p in enumerate(probes):  # padded with a vessel's first probe: no false contact
            self.probes[i] = np.vstack([p, np.repeat(p[:1], width - len(p), axis=0)])
        keel = -float(self.probes[..., 2].min())
        self.has_land = bool((z >= 0.0).any())
        # (ny, nx, 2): metres to land and to water shallower than a keel could reach, read
        # together by one bilinear lookup; FAR where there is none
        self.fields = np.stack(
            [_distances(z >= 0.0, self.mpp), _distances(z > -(keel + SHALLOW_MARGIN_M), self.mpp)],
            axis=-1,
        )
        ny, self.nx, _ = self.fields.shape
        self.flat = self.fields.reshape(-1, 2)
        self.corner = np.array([[0, 1], [self.nx, self.nx + 1]])
        self.per_m = 1.0 / self.mpp
        self.last_centre = np.array([self.nx - 1.0, ny - 1.0])
        self.last_cell = np.array([self.nx - 2, ny - 2])
        # a probe reaches this far from the origin; bilinear heights reach one pixel further
        self.reach = np.hypot(*self.probes[..., :2].transpose(2, 0, 1)).max(axis=1) + 1.5 * self.mpp
        n = len(bodies)
        self.best = np.full(n, np.inf)  # the nearest each vessel came to the shore so far
        self.anchor, self.slack2 = np.zeros((n, 2)), np.full(n, -1.0)  # -1: look at once
        self.nowhere = np.zeros(n, dtype=bool)

    def check(self, pos: Array) -> tuple[Array | None, NDArray[np.bool_]]:
        """`lookup`, skipped while no vessel can have come nearer the shore than before or
        within reach of shallow water: the fields change by at most sqrt(2) m per metre
        moved (distances are 1-Lipschitz; bilinear keeps each partial derivative <= 1), so
        after a lookup at `anchor` nothing can change until a vessel has moved `slack`."""
        off = pos[:, :2] - self.anchor
        if (rowdot(off, off) <= self.slack2).all():
            return None, self.nowhere
        shore, shallow = self.lookup(pos)
        np.minimum(self.best, shore, out=self.best)
        slack = np.minimum(shore - self.best, shallow - self.reach) / math.sqrt(2.0)
        self.anchor = pos[:, :2].copy()
        self.slack2 = np.where(slack >= 0.0, slack * slack, -1.0)
        return (shore if self.has_land else None), shallow <= self.reach

    def lookup(self, pos: Array) -> tuple[Array, Array]:
        """(distance to the shore, to water a keel could touch) (m) per vessel; FAR_M where
        the map has none, from positions (S, 3).
        Bilinear between pixel centres, clamped to the edge (`Terrain.height`'s rule): the
        four corners in one gather from the flattened fields."""
        uv = np.minimum(np.fmax(pos[:, :2] * self.per_m - 0.5, 0.0), self.last_centre)
        ij = np.minimum(uv.astype(np.intp), self.last_cell)
        f = uv - ij
        g = self.flat[(ij[:, 1] * self.nx + ij[:, 0])[:, None, None] + self.corner]  # (S, 2, 2, 2)
        west, fu = g[:, :, 0], f[:, :1, None]  # [vessel, south/north, west/east, field]
        along = west + fu * (g[:, :, 1] - west)
        d = along[:, 0] + f[:, 1:] * (along[:, 1] - along[:, 0])
        return d[:, 0], d[:, 1]

    def aground(self, pos: Array, quat: Array, near: NDArray[np.bool_]) -> NDArray[np.bool_]:
        """Which vessels have a hull probe below the terrain (pos (S, 3), quat (S, 4)); only
        those `near` shallow water are tested."""
        out = np.zeros(len(pos), dtype=bool)
        if not near.any():
            return out
        rows = np.flatnonzero(near)
        rot = matrices(np.asarray(quat[rows], dtype=np.float64))
        world = np.einsum("nij,npj->npi", rot, self.probes[rows]) + pos[rows, None, :]
        ground = self.terrain.height(world[..., 0], world[..., 1])
        out[rows] = (ground > world[..., 2]).any(axis=1)
        return out


FAR_M = 1e12  # "no such pixel on the map": finite, so the bilinear lookup stays finite


def _distances(mask: NDArray[np.bool_], mpp: float) -> Array:
    """The distance (m) from each pixel centre to the mask's nearest pixel centre."""
    if not mask.any():
        return np.full(mask.shape, FAR_M)
    return distance_transform(mask) * mpp
