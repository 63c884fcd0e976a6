"""A model's initial stability: its metacentric heights in roll and pitch, from its hulls.

Why: a centre of gravity typed too high (3 m on the 0.5 m catamaran) passed `scenario
validate MODEL.json` without a word, and the boat capsized 8 s into the run. GM = z_B +
I/V - z_G (the centre of buoyancy, the waterplane's second moment over the displaced volume,
the centre of gravity; all relative to the waterline, body frame), evaluated at the draft
where the hulls displace the mass, each hull's solid filled with small cells (a box, or a
cylinder lying along x), so any hull layout is measured, not one formula per shape.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from catabot.config.vessel import Hull, VesselModel

Array = NDArray[np.float64]
CELLS = (24, 24, 48)  # per hull: along, across, up (fine vertically: the draft is a few cm)


@dataclass(frozen=True)
class Hydrostatics:
    """Floating upright at rest: the waterplane's area and the metacentric heights."""

    waterplane_m2: float
    gm_roll_m: float
    gm_pitch_m: float


def metacentric_heights(model: VesselModel, density: float) -> tuple[float, float]:
    """(GM in roll, GM in pitch), metres, floating upright at rest; negative capsizes."""
    h = hydrostatics(model, density)
    return h.gm_roll_m, h.gm_pitch_m


def hydrostatics(
    model: VesselModel, density: float, *, cells: tuple[int, int, int] = CELLS
) -> Hydrostatics:
    """`cells` per hull (along, across, up): fewer along and across cost less and change a
    box's figures not at all (its cells fill whole columns), a cylinder's a little."""
    centre, dv, dz = _cells(model.hulls, cells)
    volume = model.mass_kg / density
    h = _waterline(centre[:, 2] - dz / 2, dz, dv, volume)
    wet = np.clip((h - (centre[:, 2] - dz / 2)) / dz, 0.0, 1.0)
    z_b = float(np.sum(dv * wet * (centre[:, 2] - dz / 2 + wet * dz / 2)) / volume)
    area, roll, pitch = _waterplane(model.hulls, h)
    z_g = model.cog_m[2]
    return Hydrostatics(area, z_b + roll / volume - z_g, z_b + pitch / volume - z_g)


def _waterplane(hulls: list[Hull], h: float) -> tuple[float, float, float]:
    """The hulls' waterplane at height h: its area (m^2) and second moments (m^4) about its
    centroid, across (roll) and along (pitch): each hull's is a rectangle, its full beam for
    a box, the chord at h for a cylinder (exact, where cells made a cylinder's width in
    steps)."""
    c = np.array([hull.center_m for hull in hulls])
    length = np.array([hull.length_m for hull in hulls])
    width = np.array([_width_at(hull, h - hull.center_m[2]) for hull in hulls])
    a = length * width
    x_f, y_f = (np.average(c[:, i], weights=a) for i in (0, 1))
    across = np.sum(length * width**3 / 12 + a * (c[:, 1] - y_f) ** 2)
    along = np.sum(width * length**3 / 12 + a * (c[:, 0] - x_f) ** 2)
    return float(a.sum()), float(across), float(along)


def _width_at(hull: Hull, dz: float) -> float:
    """The hull's waterplane width `dz` above its centre (0 above or below it)."""
    half = hull.vertical_extent_m / 2
    if abs(dz) >= half:
        return 0.0
    return hull.beam_m if hull.shape == "box" else 2.0 * float(np.sqrt(half**2 - dz**2))


def _waterline(bottom: Array, dz: Array, dv: Array, volume: float) -> float:
    """The height where the cells below it hold `volume` (bisection: it grows with h)."""
    lo, hi = float(bottom.min()), float((bottom + dz).max())
    for _ in range(60):
        mid = (lo + hi) / 2
        held = float(np.sum(dv * np.clip((mid - bottom) / dz, 0.0, 1.0)))
        lo, hi = (mid, hi) if held < volume else (lo, mid)
    return (lo + hi) / 2


def _cells(hulls: list[Hull], cells: tuple[int, int, int]) -> tuple[Array, Array, Array]:
    """Every hull's cells: centres (K, 3), volumes and heights (K,)."""
    parts = [_hull_cells(h, cells) for h in hulls]
    return tuple(np.concatenate([p[i] for p in parts]) for i in range(3))  # type: ignore[return-value]


def _hull_cells(hull: Hull, cells: tuple[int, int, int]) -> tuple[Array, Array, Array]:
    size = np.array([hull.length_m, hull.beam_m, hull.vertical_extent_m])
    step = size / np.array(cells)
    axes = [(np.arange(n) + 0.5) * s - d / 2 for n, s, d in zip(cells, step, size, strict=True)]
    grid = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)
    if hull.shape == "cylinder":  # lying along x: keep the cells inside its circle
        grid = grid[grid[:, 1] ** 2 + grid[:, 2] ** 2 <= (hull.beam_m / 2) ** 2]
    k = len(grid)
    centre = grid + np.asarray(hull.center_m)
    return centre, np.full(k, np.prod(step)), np.full(k, step[2])
