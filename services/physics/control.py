"""Velocity control: desired surge speed and yaw rate → normalised thruster commands.

Feed-forward from the vessel's own damping law (the thrust that holds that speed in
steady state) plus a PI term on the error, then a least-squares allocation over the
thrusters' surge force and yaw moment arms, clamped to each thruster's limits.
"""

from __future__ import annotations

import numpy as np

from catabot.vessel import VesselModel


class TwistController:
    def __init__(
        self, model: VesselModel, *, dt_s: float, kp: float = 2.0, ki: float = 0.5
    ) -> None:
        lin, quad = model.damping.linear, model.damping.quadratic
        self.damp = np.array([[lin[0], quad[0]], [lin[5], quad[5]]])
        self.inertia = np.array([model.mass_kg, model.inertia_kgm2[2]])
        self.dt_s, self.kp, self.ki = dt_s, kp, ki
        self.integral = np.zeros(2)
        yaw = np.array([t.yaw_rad for t in model.thrusters])
        pos = np.array([t.position_m for t in model.thrusters]).reshape(-1, 3)
        self.alloc = np.vstack([np.cos(yaw), pos[:, 0] * np.sin(yaw) - pos[:, 1] * np.cos(yaw)])
        self.pinv = np.linalg.pinv(self.alloc)
        self.fwd = np.array([t.max_forward_n for t in model.thrusters])
        self.rev = np.array([t.max_reverse_n for t in model.thrusters])

    def command(self, target: tuple[float, float], measured: tuple[float, float]) -> np.ndarray:
        """Normalised commands in [-1, 1] for (surge m/s, yaw rate rad/s) targets."""
        goal, now = np.asarray(target), np.asarray(measured)
        error = goal - now
        feed = self.damp[:, 0] * goal + self.damp[:, 1] * goal * np.abs(goal)
        self.integral = np.clip(self.integral + error * self.dt_s, -5.0, 5.0)
        wrench = feed + self.inertia * (self.kp * error + self.ki * self.integral)
        forces = self.pinv @ wrench
        limit = np.where(forces >= 0, self.fwd, self.rev)
        return np.clip(forces / np.maximum(limit, 1e-9), -1.0, 1.0)
