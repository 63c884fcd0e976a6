"""Where and how a vessel starts: its pose in `map` and its body-frame velocity at t = 0.

Every vessel used to start at rest on the calm surface (z = 0, level); free-decay and drop
tests and a boat already under way need the rest. Physics places each body exactly so
(services/physics/setup.py) and `World.start_states` says the same, so the first recorded
state follows from it. A floating vessel may start off its equilibrium: it then heaves,
rolls or pitches back as its hydrostatics dictate.
"""

from __future__ import annotations

import math

from pydantic import Field

from catabot.bus.checks import MAX_RATE_RADPS, MAX_SPEED_MPS
from catabot.config.base import Angle, Strict


class Pose(Strict):
    """Start pose in `map` (ENU). z_m 0 is the body origin on the surface at its point (the
    calm level, or the waves' surface at t = 0: `World.start_states`), where a vessel then
    settles to its draft; roll and pitch turn the body about its own x and y axes
    (map <- body = Rz(yaw) Ry(pitch) Rx(roll))."""

    x_m: float = 0.0
    y_m: float = 0.0
    z_m: float = Field(
        0.0, ge=-20.0, le=100.0, description="height of the body origin above the surface at t = 0"
    )
    roll_rad: float = Field(0.0, ge=-math.pi, le=math.pi)
    pitch_rad: float = Field(0.0, ge=-math.pi / 2, le=math.pi / 2)
    yaw_rad: Angle = 0.0

    @property
    def level_at_surface(self) -> bool:
        """True for the start every vessel had before z, roll and pitch existed."""
        return self.z_m == 0.0 and self.roll_rad == 0.0 and self.pitch_rad == 0.0


class Velocity(Strict):
    """Body-frame velocity at t = 0 (FLU: surge forward, sway left, heave up; roll, pitch
    and yaw rates about the body's x, y, z), as `VesselState` reports it."""

    surge_mps: float = Field(0.0, ge=-MAX_SPEED_MPS, le=MAX_SPEED_MPS)
    sway_mps: float = Field(0.0, ge=-MAX_SPEED_MPS, le=MAX_SPEED_MPS)
    heave_mps: float = Field(0.0, ge=-MAX_SPEED_MPS, le=MAX_SPEED_MPS)
    roll_rate_radps: float = Field(0.0, ge=-MAX_RATE_RADPS, le=MAX_RATE_RADPS)
    pitch_rate_radps: float = Field(0.0, ge=-MAX_RATE_RADPS, le=MAX_RATE_RADPS)
    yaw_rate_radps: float = Field(0.0, ge=-MAX_RATE_RADPS, le=MAX_RATE_RADPS)

    @property
    def linear(self) -> tuple[float, float, float]:
        return (self.surge_mps, self.sway_mps, self.heave_mps)

    @property
    def angular(self) -> tuple[float, float, float]:
        return (self.roll_rate_radps, self.pitch_rate_radps, self.yaw_rate_radps)

    @property
    def at_rest(self) -> bool:
        return not any((*self.linear, *self.angular))
