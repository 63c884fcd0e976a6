"""Environment loads for every body at once: current, wind, moorings and added mass.

PhysicsWorld calls `current_world` (the current at each body, which damping acts against),
then `total` with the sum of the other wrenches. Each part is skipped outright when it cannot act
(no field, a calm wind, nil current, no added mass), so an empty environment costs nothing.

Moorings: a moored body (a buoy) is held by a horizontal spring of zero rest length between
its body origin (at the waterline) and its anchor's (x, y), hardening like a chain's catenary:
F = -k x (1 + (|x| / MOORING_SCOPE_M)^2), x the offset. A slack chain barely resists small
motions, so k is set per body for a surge period of MOORING_PERIOD_S on the spring, k = (m +
A11)(2 pi / T)^2, far above any wave period: a moored buoy swings with the water as a free
one does. A fixed 100 N/m put the buoy's period at 4.9 s, inside the wind-wave band, and it
swung 1.54 times the water's 0.18 m in a 6 s regular wave. The hardening holds it on station
under steady loads: 3.0 m off its anchor in a 0.5 m/s current, 5 m in 1 m/s (the bundled
buoy). Acting at the waterline, it does not heel the buoy.
"""

from __future__ import annotations

import copy
from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from catabot.config.vessel import VesselModel
from catabot.world.environment import CurrentField, WindField
from services.physics.added_mass import AddedMass
from services.physics.hydro import Array
from services.physics.wind import wind_gains, wind_wrench

MOORING_PERIOD_S = 30.0  # a moored body's surge period on its mooring: 3 x the longest preset's
MOORING_SCOPE_M = 3.0  # offset at which the mooring pulls twice as hard as its linear part


def mooring_force(offset: Array, k: Array) -> Array:
    """The pull (M, 2) of moorings of stiffness k (M,) on bodies offset (M, 2) from their
    anchors (see the module docstring)."""
    reach = np.sum(offset * offset, axis=1) / MOORING_SCOPE_M**2
    return -(k * (1.0 + reach))[:, None] * offset


class EnvironmentLoads:
    """Per-step environment forces; `advance` moves the fields' own state once per step."""

    def __init__(
        self,
        models: Sequence[VesselModel],
        *,
        gravity: float,
        current: CurrentField | None = None,
        wind: WindField | None = None,
        anchors: Array | None = None,
    ) -> None:
        n = len(models)
        self.current = None if current is None or current.is_zero else current
        self.wind = wind
        self.wind_gains = wind_gains(models, wind.air_density) if wind is not None else None
        self.added_mass = AddedMass(models, gravity)
        anchor_xy = np.full((n, 2), np.nan) if anchors is None else np.asarray(anchors, float)
        self.moored = np.flatnonzero(np.isfinite(anchor_xy).all(axis=1))
        self.anchor_xy = anchor_xy[self.moored]
        surge_mass = np.array([m.mass_kg + m.added_mass[0] for m in models], dtype=np.float64)
        self.mooring_k = surge_mass[self.moored] * (2.0 * np.pi / MOORING_PERIOD_S) ** 2
        self._zero_current = np.zeros((n, 3))
        self._still_air = np.zeros((n, 2))

    def take(self, rows: NDArray[np.intp]) -> EnvironmentLoads:
        """The loads of bodies `rows` (sorted) alone, sharing this one's fields (forces.py);
        taken again after any run-time change."""
        sub = copy.copy(self)
        if self.wind_gains is not None:
            sub.wind_gains = self.wind_gains[rows]
        sub.added_mass = self.added_mass.take(rows)
        pick = np.flatnonzero(np.isin(self.moored, rows))
        sub.moored = np.searchsorted(rows, self.moored[pick])
        sub.anchor_xy, sub.mooring_k = self.anchor_xy[pick], self.mooring_k[pick]
        sub._zero_current, sub._still_air = np.zeros((len(rows), 3)), np.zeros((len(rows), 2))
        return sub

    def set_uniform_current(self, velocity_mps: tuple[float, float]) -> None:
        """A run-time change of the uniform current (`catabot set current`); a map stays."""
        if self.current is None:
            self.current = CurrentField(velocity_mps)
        else:
            self.current.uniform = np.array(velocity_mps, dtype=np.float64)

    def current_world(self, pos: Array) -> Array:
        """The steady current at each body origin, world frame (N, 3); zeros without one."""
        if self.current is None:
            return self._zero_current
        out = np.zeros((len(pos), 3))
        out[:, :2] = self.current.velocity_at(pos[:, 0], pos[:, 1])
        return out

    def total(
        self, rot: Array, pos: Array, nu: Array, water_b: Array, base: Array, *,
        wet: Array | None = None,
    ) -> Array:  # fmt: skip
        """base + wind + moorings + added mass, body frame (N, 6).

        water_b is the water's velocity at each body origin in the body frame: the current
        and the waves' orbital velocity, so the added mass's Munk terms see the flow past
        the hull (added_mass.py). `wet`: the added mass's share for each body
        (forces.wetness; None: all of it).
        """
        total = base
        if self.wind is not None and self.wind_gains is not None:
            # In still air a moving hull still meets the air: the apparent wind is -velocity,
            # so the drag is continuous as the wind goes to zero (it used to switch off).
            calm = self.wind.is_calm
            wind_xy = self._still_air if calm else self.wind.velocity_at(pos[:, 0], pos[:, 1])
            total = total + wind_wrench(self.wind_gains, rot, wind_xy, nu)
        if self.moored.size:
            total = total + self._mooring(rot, pos)
        if self.added_mass.active:
            total = total + self.added_mass.wrench(rot, nu, water_b, total, wet=wet)
        return total

    def advance(self, dt_s: float) -> None:
        """Advance the fields' random state once per physics step."""
        if self.wind is not None:
            self.wind.advance(dt_s)

    def _mooring(self, rot: Array, pos: Array) -> Array:
        """Spring wrench of the moored bodies, zero rows elsewhere."""
        out = np.zeros((len(pos), 6))
        rows = self.moored
        f = mooring_force(pos[rows, :2] - self.anchor_xy, self.mooring_k)  # world frame, (M, 2)
        out[rows, :3] = f[:, 0:1] * rot[rows, 0, :] + f[:, 1:2] * rot[rows, 1, :]
        return out
