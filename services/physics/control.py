"""Velocity control: desired surge speed and yaw rate → normalised thruster commands.

Feed-forward from the vessel's own damping law and its windage in still air (the thrust
that holds that speed in steady state, catabot/world/course.py) plus a PI term on the
error, scaled by the effective inertia (rigid plus added mass), then an allocation over the
thrusters' surge force and yaw moment arms.

Allocation gives the yaw moment priority: when the thrusters cannot deliver both, the
surge part is scaled down until every thruster is within its limits (a boat that must
turn keeps turning and slows), and the yaw part alone is scaled if even it is too much.
Every output is within [-1, 1], i.e. within each thruster's forward/reverse limit.

Anti-windup by conditional integration: the integral only accumulates on steps where the
allocation is not saturated, so a long acceleration at full thrust does not leave a
wound-up integrator that overshoots for a minute afterwards.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from catabot.config.vessel import VesselModel
from catabot.world.course import surge_drag
from services.physics import kernels

Array = NDArray[np.float64]


class TwistController:
    def __init__(
        self, model: VesselModel, *, dt_s: float, kp: float = 2.0, ki: float = 0.5
    ) -> None:
        lin, quad = model.damping.linear, model.damping.quadratic
        self.damp = np.array([surge_drag(model), [lin[5], quad[5]]])
        # Effective surge mass and yaw inertia about the body origin, added mass included.
        x_g, y_g, _ = model.cog_m
        yaw_inertia = model.inertia_kgm2[2] + model.mass_kg * (x_g * x_g + y_g * y_g)
        added = model.added_mass
        self.inertia = np.array([model.mass_kg + added[0], yaw_inertia + added[5]])
        self.dt_s, self.kp, self.ki = dt_s, kp, ki
        self.integral = np.zeros(2)
        yaw = np.array([t.yaw_rad for t in model.thrusters])
        pos = np.array([t.position_m for t in model.thrusters]).reshape(-1, 3)
        self.alloc = np.vstack([np.cos(yaw), pos[:, 0] * np.sin(yaw) - pos[:, 1] * np.cos(yaw)])
        self.pinv = np.linalg.pinv(self.alloc)
        self.fwd = np.array([t.max_forward_n for t in model.thrusters])
        self.rev = np.array([t.max_reverse_n for t in model.thrusters])

    def command(self, target: tuple[float, float], measured: tuple[float, float]) -> Array:
        """Normalised commands in [-1, 1] for (surge m/s, yaw rate rad/s) targets."""
        goal, now = np.asarray(target, dtype=np.float64), np.asarray(measured, dtype=np.float64)
        error = goal - now
        feed = self.feed_forward(goal)
        trial = np.clip(self.integral + error * self.dt_s, -5.0, 5.0)
        wrench = feed + self.inertia * (self.kp * error + self.ki * trial)
        forces, saturated = self.allocate(wrench)
        if not saturated:
            self.integral = trial
        limit = np.where(forces >= 0, self.fwd, self.rev)
        return np.clip(forces / np.maximum(limit, 1e-9), -1.0, 1.0)

    def feed_forward(self, goal: Array) -> Array:
        """The [surge force, yaw moment] that holds (surge, yaw rate) `goal` in steady state."""
        out: Array = self.damp[:, 0] * goal + self.damp[:, 1] * goal * np.abs(goal)
        return out

    def allocate(self, wrench: Array) -> tuple[Array, bool]:
        """Thruster forces (N) for a [surge force, yaw moment] wrench, yaw first; and whether
        any part had to be scaled down to respect the limits."""
        yaw_part = self.pinv[:, 1] * wrench[1]
        s_yaw = _largest_scale(np.zeros_like(yaw_part), yaw_part, -self.rev, self.fwd)
        yaw_part = s_yaw * yaw_part
        surge_part = self.pinv[:, 0] * wrench[0]
        s_surge = _largest_scale(yaw_part, surge_part, -self.rev, self.fwd)
        return yaw_part + s_surge * surge_part, bool(s_yaw < 1.0 or s_surge < 1.0)


def _largest_scale(base: Array, step: Array, lo: Array, hi: Array) -> float:
    """Largest s in [0, 1] with lo <= base + s * step <= hi for every thruster (base inside)."""
    room = np.where(step > 0, hi - base, np.where(step < 0, lo - base, np.inf))
    with np.errstate(divide="ignore", invalid="ignore"):
        bounds = np.where(step != 0, room / np.where(step != 0, step, 1.0), np.inf)
    return float(np.clip(np.min(bounds, initial=1.0), 0.0, 1.0))


class TwistControllerBank:
    """The same law as TwistController for many vessels at once (one compiled loop a tick):
    with 100 traffic boats a controller call per boat would cost more than the physics."""

    def __init__(self, models: list[VesselModel], *, dt_s: float) -> None:
        self.single = single = [TwistController(m, dt_s=dt_s) for m in models]  # reach.py too
        width = max(len(c.fwd) for c in single)
        self.count = np.array([len(c.fwd) for c in single])
        self.damp = np.stack([c.damp for c in single])  # (N, 2, 2)
        self.inertia = np.stack([c.inertia for c in single])  # (N, 2)
        self.pinv = np.zeros((len(single), width, 2))
        self.fwd, self.rev = np.zeros((len(single), width)), np.zeros((len(single), width))
        for i, c in enumerate(single):
            t = len(c.fwd)
            self.pinv[i, :t], self.fwd[i, :t], self.rev[i, :t] = c.pinv, c.fwd, c.rev
        self.dt_s, self.kp, self.ki = dt_s, single[0].kp, single[0].ki
        self.integral = np.zeros((len(single), 2))

    def command(self, rows: NDArray[np.intp], target: Array, measured: Array) -> Array:
        """Normalised commands (len(rows), width) for vessels `rows`; padding columns are 0
        (kernels.twist_commands: the law above, one compiled loop over the rows)."""
        tables = (self.damp, self.inertia, self.pinv, self.rev, self.fwd)
        gains = (float(self.dt_s), float(self.kp), float(self.ki))
        setpoints = (np.ascontiguousarray(target, dtype=np.float64),
                     np.ascontiguousarray(measured, dtype=np.float64))  # fmt: skip
        rows = np.ascontiguousarray(rows, dtype=np.intp)
        return kernels.twist_commands(tables, gains, self.integral, rows, setpoints)
