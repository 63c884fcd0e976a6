"""Wind: a global wind plus circle/polygon zones, with seeded Gauss-Markov gusts per source.

A "source" is the global wind or one zone. Each has a mean speed, a direction (ENU, the way
the wind blows, see catabot.config.environment) and its own gust state g. A point takes the
source that covers it: the last listed zone containing it, else the global wind; its wind
is max(speed + g, 0) along the source's direction. Gusts are uniform in space.

Gusts: g follows an Ornstein-Uhlenbeck process discretised exactly,
    g[k+1] = phi * g[k] + sigma * sqrt(1 - phi^2) * n[k],   phi = exp(-dt / tau),
so its standard deviation is sigma and its autocorrelation exp(-lag / tau) for any dt.
The initial g is drawn from the stationary law. Randomness (DESIGN.md §2): one generator
`seeding.rng(seed, "wind")`; each `advance` draws exactly one
normal per source (even with sigma = 0), so the stream per tick depends only on the seed
and the number of zones.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray

from catabot.config.environment import EnvironmentConfigError, WindConfig, WindZone
from catabot.config.geometry import Polygon, points_in_circle
from catabot.world import seeding

Array = NDArray[np.float64]
Mask = NDArray[np.bool_]
ZoneTest = Callable[[Array, Array], Mask]


class WindField:
    """The wind at any points of `map`, advanced once per physics step."""

    def __init__(self, config: WindConfig, *, seed: int) -> None:
        self.config = config
        self.air_density = config.air_density_kg_m3
        sources = [(config.speed_mps, config.toward_rad, config.gust_std_mps)]
        for zone in config.zones:
            std = config.gust_std_mps if zone.gust_std_mps is None else zone.gust_std_mps
            sources.append((zone.speed_mps, zone.toward_rad, std))
        speed, toward, std = np.array(sources, dtype=np.float64).T
        self.mean_speed = speed
        self.direction = np.stack([np.cos(toward), np.sin(toward)], axis=1)  # (S, 2)
        self.gust_std = std
        self.tau = config.gust_time_constant_s
        self._zones = [_zone_test(z) for z in config.zones]
        self._rng = seeding.rng(seed, "wind")
        self.gust = self.gust_std * self._rng.standard_normal(len(sources))
        self._phi_dt = (math.nan, 0.0, 0.0)  # (dt, phi, sqrt(1 - phi^2)) cache

    def set_global(
        self, *, speed_mps: float | None = None, toward_rad: float | None = None
    ) -> None:
        """A run-time change of the global mean wind (`catabot set wind.*`); its gust process
        goes on as it was, so the random stream is the same with or without the change."""
        if speed_mps is not None:
            self.mean_speed[0] = speed_mps
        if toward_rad is not None:
            self.direction[0] = (math.cos(toward_rad), math.sin(toward_rad))

    @property
    def is_calm(self) -> bool:
        """True when no source can ever blow (the physics then skips the field: still air)."""
        return not (np.any(self.mean_speed) or np.any(self.gust_std))

    def advance(self, dt_s: float) -> None:
        """Move every gust process forward by dt (one draw per source)."""
        if dt_s != self._phi_dt[0]:
            if not (math.isfinite(dt_s) and dt_s > 0):
                raise EnvironmentConfigError(f"wind advance: dt_s must be > 0 (got {dt_s})")
            phi = math.exp(-dt_s / self.tau)
            self._phi_dt = (dt_s, phi, math.sqrt(-math.expm1(-2.0 * dt_s / self.tau)))
        _, phi, gain = self._phi_dt
        noise = self._rng.standard_normal(self.gust.shape)
        self.gust = phi * self.gust + gain * self.gust_std * noise

    def source_at(self, x: Array, y: Array) -> NDArray[np.intp]:
        """Index of the source covering each point: 0 global, k the k-th zone (1-based)."""
        xs, ys = np.asarray(x, dtype=np.float64), np.asarray(y, dtype=np.float64)
        source = np.zeros(xs.shape, dtype=np.intp)
        for k, contains in enumerate(self._zones, start=1):
            source[contains(xs, ys)] = k  # later zones overwrite earlier ones
        return source

    def velocity_at(self, x: Array, y: Array) -> Array:
        """Wind velocity (m/s, world frame) at points of any shape: shape x.shape + (2,)."""
        speed = np.maximum(self.mean_speed + self.gust, 0.0)
        velocity = speed[:, None] * self.direction  # (S, 2)
        if not self._zones:
            out = np.empty((*np.shape(x), 2))
            out[...] = velocity[0]
            return out
        return np.asarray(velocity[self.source_at(x, y)])


def _zone_test(zone: WindZone) -> ZoneTest:
    """A vectorised membership test (x, y) -> mask for one zone."""
    if zone.shape == "circle":
        assert zone.center_m is not None and zone.radius_m is not None
        center, radius = zone.center_m, zone.radius_m

        def in_circle(x: Array, y: Array) -> Mask:
            return points_in_circle(x, y, center, radius)

        return in_circle
    assert zone.vertices_m is not None
    return Polygon(zone.vertices_m).contains
