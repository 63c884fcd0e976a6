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
    surface: WaterHeight


class SeaSampler:
    """Per world: the column layout's radii; per sea (`use`): the method; per step: `sample`."""

    def __init__(self, models: Sequence[VesselModel], bottom_m: Array) -> None:
        """`bottom_m`: (N, C, 3) body-frame column bottoms as `hydro.build_columns` lays
        them out (padding columns sit at the body origin)."""
        self._radius_m = float(np.linalg.norm(bottom_m, axis=2).max(initial=0.0))
        self._patches = PatchLayout(models, bottom_m)
        self._waves: WaveField | None = None
        self._order: int | None = None

    def use(self, waves: WaveField | None) -> None:
        """The sea from now on (at the start, and at a run-time change of the waves)."""
        self._waves = None if waves is None or waves.is_calm else waves
        if self._waves is None:
            return
        self._order = choose_order(self._waves, self._radius_m)
        if self._order is not None:
            self._row, self._weights = expansion(self._waves, self._order)
            self._pq = exponents(self._order)
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

    def sample(self, pos: Array, time_s: float) -> SeaSample:
        """The water of this step for bodies at `pos` (N, 3, map)."""
        waves = self._waves
        if waves is None:
            return SeaSample(None, water_height)
        if self._order is None:
            velocity = waves.velocity(pos[:, 0], pos[:, 1], pos[:, 2], time_s)
            return SeaSample(velocity, self._surface)
        phase = waves.phases(pos[:, 0], pos[:, 1], time_s)
        cos, sin = np.cos(phase), np.sin(phase)
        coef = cos @ self._weights[0]
        coef += sin @ self._weights[1]  # (N, T): before `orbital` scales cos and sin
        velocity = waves.orbital(cos, sin, pos[:, 2])
        return SeaSample(velocity, _Expansions(coef, self._row, self._pq, pos))


class _Expansions:
    """eta(x, y) at the (N, C) columns from each vessel's expansion about its origin;
    `at_columns` is the same, compiled, for the buoyancy columns themselves (hydro.py)."""

    def __init__(
        self, coef: F32, row: Rows, pq: tuple[NDArray[np.intp], NDArray[np.intp]], pos: Array
    ) -> None:
        """coef (N, T): each vessel's Taylor coefficients, in `row`'s order; pq: the (p, q)
        of each (`surface.exponents`)."""
        self._coef, self._row = coef.T[:, :, None], row
        self._x0, self._y0 = pos[:, 0:1], pos[:, 1:2]
        p, q = pq
        self._grid = np.zeros((len(coef), p.max() + 1, p.max() + 1), np.float32)
        self._grid[:, p, q] = coef  # row's order is exponents'

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
        eta = horner(self._coef, self._row, dx, dy)
        out = np.empty(dx.shape)
        out[...] = eta  # broadcast (an order-0 sea) and widened in one pass
        return out
