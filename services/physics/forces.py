"""The force model's per-body tables and the body-frame wrench they give, for the awake bodies.

Why: a sleeping buoy (sleep.py) is frozen in DART, so the forces on it are never applied;
computing them anyway cost the waypoint row of Table II (101 boats, 275 buoys) ~0.35 ms a
step, as much as 100 boats' hydrodynamics. `AwakeTables` keeps the tables (columns, damping,
wind, moorings, added mass) of the awake bodies only, taken again whenever a body falls
asleep or wakes; every law is row by row, so an awake body's wrench is the same, bit for
bit, whoever else is awake. Sleeping bodies get zero rows. Waves never coexist with sleep
(sleep.py needs a steady sea and wakes every body when the sea changes), so the sea, whose
hull patches are laid out for every row, is only ever sampled for a subset on calm water.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from services.physics import kernels
from services.physics.hydro import Array, Columns, buoyancy_wrench, column_heights, damping_wrench
from services.physics.loads import EnvironmentLoads
from services.physics.sea import SeaSampler
from services.physics.sleep import Sleep
from services.physics.wave_pull import PullTable, wave_pull
from services.physics.wet import ThrustLoad, wetness

Rows = NDArray[np.intp]
OTHER = "wind, moorings and added mass"
PULL = "waves' pull"


@dataclass(frozen=True)
class ForceTables:
    """Everything per body the force laws read: (N, ...) rows, one per body."""

    columns: Columns
    linear: Array  # (N, 6) damping coefficients
    quadratic: Array
    loads: EnvironmentLoads
    weight_n: Array  # (N,) m g: the buoyancy that floats each body
    lift: Array | None = None  # (N, 2) [Y_uv, N_uv]; None: no body has any
    pull: PullTable | None = None  # what the waves pull on each hull, and where (wave_pull)

    def take(self, rows: Rows) -> ForceTables:
        """The tables of bodies `rows` (sorted), in that order."""
        return ForceTables(
            self.columns.take(rows),
            self.linear[rows],
            self.quadratic[rows],
            self.loads.take(rows),
            self.weight_n[rows],
            None if self.lift is None else self.lift[rows],
            None if self.pull is None else self.pull.take(rows),
        )


@dataclass(frozen=True)
class BodyMotion:
    """The bodies' poses and world-frame velocities ([angular, linear], DART's order)."""

    rot: Array  # (N, 3, 3) body to world
    pos: Array  # (N, 3)
    vel_w: Array  # (N, 6)

    def take(self, rows: Rows) -> BodyMotion:
        return BodyMotion(self.rot[rows], self.pos[rows], self.vel_w[rows])


class AwakeTables:
    """The tables of the awake bodies, taken again only when the sleeping set changes."""

    def __init__(self, full: ForceTables) -> None:
        self.full = full
        self._version = -1
        self._rows: Rows | None = None
        self._part = full

    def of(self, sleep: Sleep) -> tuple[Rows | None, ForceTables]:
        """The awake rows (None: every body) and their tables."""
        if sleep.version != self._version:
            self._version = sleep.version
            asleep = sleep.rows_asleep()
            self._rows = np.flatnonzero(~asleep) if asleep.any() else None
            self._part = self.full if self._rows is None else self.full.take(self._rows)
        return self._rows, self._part


@dataclass(frozen=True)
class Fluid:
    density: float
    gravity: float


def body_wrench(
    tables: ForceTables,
    motion: BodyMotion,
    sea: SeaSampler,
    thrust: ThrustLoad,
    *,
    fluid: Fluid,
    time_s: float,
) -> tuple[dict[str, Array], Array | None]:
    """Each load's body-frame wrench (N, 6), Fossen order, about the origin, and their sum
    under "total": buoyancy, damping against the water, thrust, then wind, moorings and
    added mass (which needs every other load); and each hull's `wetness` (None: all wet).
    Damping and added mass act on a hull as far as it is in the water; thrusters push only
    under water."""
    nu = kernels.body_twist(motion.rot, motion.vel_w)
    current_w = tables.loads.current_world(motion.pos)
    water = sea.sample(motion.pos, time_s, motion.rot)
    water_w = current_w  # plus the waves' orbital velocity at each body origin: damping
    if water.velocity_w is not None:  # and added mass act on motion relative to the water
        water_w = water_w + water.velocity_w
    water_b = kernels.to_body(motion.rot, np.ascontiguousarray(water_w))
    cols, rot = tables.columns, motion.rot
    eta = column_heights(cols, rot, motion.pos, time_s=time_s, surface=water.surface)
    buoyancy = buoyancy_wrench(cols, rot, motion.pos, density=fluid.density,
                               gravity=fluid.gravity, eta=eta)  # fmt: skip
    wet = wetness(buoyancy, motion.rot, tables.weight_n)
    damping = damping_wrench(nu, tables.linear, tables.quadratic, water_b, tables.lift)
    loads = {
        "buoyancy": buoyancy,
        "damping": damping if wet is None else damping * wet[:, None],
        "thrust": thrust.wrench(motion.rot, motion.pos, water.at_points, time_s),
    }
    base = loads["buoyancy"] + loads["damping"] + loads["thrust"]
    if water.velocity_w is not None and tables.pull is not None:  # waves
        pull = wave_pull(tables.pull, cols, rot, eta, gravity=fluid.gravity, wet=wet)
        loads[PULL] = pull
        base = base + pull
    total = tables.loads.total(motion.rot, motion.pos, nu, water_b, base, wet=wet)
    loads[OTHER] = total - base
    loads["total"] = total
    return loads, wet


def spread(loads: dict[str, Array], rows: Rows, count: int) -> dict[str, Array]:
    """Wrenches of bodies `rows` as (count, 6) arrays, zero elsewhere (sleeping bodies)."""
    out = {}
    for name, part in loads.items():
        full = np.zeros((count, 6))
        full[rows] = part
        out[name] = full
    return out
