"""The sea as physics samples it each step: one choice of method per sea state.

Three ways to get the surface at the buoyancy columns, the cheapest that keeps within
surface.TOLERANCE_M for this sea (surface.py has the bound): one Taylor expansion about each
vessel's origin, sharing its cosines with the orbital velocity there; patches along each
hull; the exact sum. Calm water is zero height and still water, as before any of this.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from catabot.config.vessel import VesselModel
from catabot.world.waves import WaveField
from services.physics import kernels
from services.physics.hull_average import HullAverage
from services.physics.hydro import Array, WaterHeight, water_height
from services.physics.surface import (
    F32,
    PatchLayout,
    Rows,
    choose_order,
    expansion,
    exponents,
    horner,
)


@dataclass(frozen=True)
class SeaSample:
    """One step's water: orbital velocity at each body origin (None: still water, so the
    current alone, bit for bit as without waves) and the surface at the columns."""

    velocity_w: Array | None
    surface: WaterHeight  # at the buoyancy columns (the layout the method was chosen for)
    at_points: WaterHeight = water_height  # at points near each body (its thrusters), (N, k)


class SeaSampler:
    """Per world: the column layout's radii; per sea (`use`): the method; per step: `sample`."""

    def __init__(self, models: Sequence[VesselModel], bottom_m: Array, area_m2: Array) -> None:
        """`bottom_m`: (N, C, 3) body-frame column bottoms as `hydro.build_columns` lays
        them out (padding columns sit at the body origin), `area_m2` (N, C) their areas."""
        self._radius_m = float(np.linalg.norm(bottom_m, axis=2).max(initial=0.0))
        self._patches = PatchLayout(models, bottom_m)
        self._hulls = HullAverage(bottom_m, area_m2)
        self._waves: WaveField | None = None
        self._order: int | None = None

    def use(self, waves: WaveField | None) -> None:
        """The sea from now on (at the start, and at a run-time change of the waves)."""
        self._waves = None if waves is None or waves.is_calm else waves
        if self._waves is None:
            return
        self._hulls.use(self._waves)
        self._order = choose_order(self._waves, self._radius_m)
        if self._order is not None:
            self._row, weights = expansion(self._waves, self._order)
            self._pq = exponents(self._order)
            self._to_grid = _grid_weights(weights, self._pq, self._order)
        else:
            self._surface = self._patches.surface(self._waves)

    @property
    def calm(self) -> bool:
        return self._waves is None

    @property
    def method(self) -> str:
        """Which of the three this sea uses (for tests and the benchmark's table)."""
        if self._waves is None:
            return "calm"
        if self._order is not None:
            return f"vessel expansions, order {self._order}"
        return "exact sum" if self._surface == self._waves.height else "hull patches"

    def sample(self, pos: Array, time_s: float, rot: Array) -> SeaSample:
        """The water of this step for bodies at `pos` (N, 3, map) turned by `rot` (N, 3, 3):
        the orbital velocity averaged over each hull's waterplane (hull_average.py)."""
        waves = self._waves
        if waves is None:
            return SeaSample(None, water_height)
        phase = waves.phases(pos[:, 0], pos[:, 1], time_s)
        m = phase.shape[1]
        trig = np.empty((len(phase), 2 * m), np.float32)  # [cos | sin]: one matmul below
        cos, sin = np.cos(phase, out=trig[:, :m]), np.sin(phase, out=trig[:, m:])
        eta = waves.height_of(cos)  # at each origin, for the stretching: before the average
        if self._order is not None:
            grid = (trig @ self._to_grid).reshape(len(phase), self._order + 1, self._order + 1)
            surface: WaterHeight = _Expansions(grid, self._row, self._pq, pos)
        else:
            surface = self._surface
        velocity = waves.orbital(*self._hulls.average(cos, sin, rot), pos[:, 2], eta=eta)
        at_points = waves.height if self._order is None else surface  # thrusters: within
        return SeaSample(velocity, surface, at_points)  # the columns' radius


class _Expansions:
    """eta(x, y) at the (N, C) columns from each vessel's expansion about its origin;
    `at_columns` is the same, compiled, for the buoyancy columns themselves (hydro.py)."""

    def __init__(
        self, grid: F32, row: Rows, pq: tuple[NDArray[np.intp], NDArray[np.intp]], pos: Array
    ) -> None:
        """grid (N, n + 1, n + 1): each vessel's Taylor coefficient of dx^p dy^q at [p, q]
        (zero where p + q > n); row and pq: the monomials' rows (`surface.expansion`) and
        their (p, q) (`surface.exponents`)."""
        self._grid, self._row, self._pq = grid, row, pq
        self._x0, self._y0 = pos[:, 0:1], pos[:, 1:2]

    def at_columns(self, rot: Array, bottom_m: Array) -> Array:
        """eta at columns `bottom_m` (N, 3, C, body frame) of the bodies (turned by `rot`)
        about whose origins it was expanded."""
        return kernels.expansion_heights(rot, bottom_m, self._grid)

    def __call__(self, x: Array, y: Array, time_s: float) -> Array:
        """eta at world points: the array form of `at_columns`, for a caller that has world
        points (the WaterHeight contract; tests hold the two within float32 rounding)."""
        del time_s  # the expansion is of this step's surface
        # float64 differences rounded to float32 as they are written: the same bits as
        # (x - x0).astype(np.float32), without the float64 temporary
        dx = np.subtract(x, self._x0, out=np.empty(x.shape, np.float32), casting="same_kind")
        dy = np.subtract(y, self._y0, out=np.empty(y.shape, np.float32), casting="same_kind")
        p, q = self._pq
        eta = horner(self._grid[:, p, q].T[:, :, None], self._row, dx, dy)
        out = np.empty(dx.shape)
        out[...] = eta  # broadcast (an order-0 sea) and widened in one pass
        return out


def _grid_weights(
    weights: tuple[F32, F32], pq: tuple[NDArray[np.intp], NDArray[np.intp]], order: int
) -> F32:
    """(2M, (n + 1)^2) float32: a vessel's [cos | sin] of the phases at its origin times
    this is its coefficient grid, flattened (`surface.expansion`'s matrices, their columns
    moved to [p, q]): one matmul a step, nothing scattered."""
    (on_cos, on_sin), (p, q) = weights, pq
    out = np.zeros((2 * on_cos.shape[0], (order + 1) ** 2), np.float32)
    out[:, p * (order + 1) + q] = np.concatenate([on_cos, on_sin])
    return out
