"""Scenario settings for water current and wind (DESIGN.md §6): validated, frozen models.

Conventions, fixed here once for every consumer (physics, sensors, visualisation):
- Every velocity is a vector in the world frame `map` (ENU: x east, y north), in m/s.
- A direction angle is the ENU angle of the direction the flow goes TOWARD, counter-clockwise
  from east (x): `toward_rad = 0` is a wind blowing toward the east (a "west wind" in
  meteorological words), `pi/2` blows toward the north. This is VRX's convention too. From a
  meteorological direction theta_from (degrees clockwise from north the wind comes FROM):
  toward_rad = radians(270 - theta_from).
"""

from __future__ import annotations

import math
from typing import Annotated, Literal

from pydantic import Field, field_validator, model_validator

from catabot.config.base import Angle, ConfigError, Strict
from catabot.config.geometry import polygon_area, polygon_self_intersects

Vec2 = tuple[float, float]
NonNegative = Annotated[float, Field(ge=0)]
Positive = Annotated[float, Field(gt=0)]
MAX_CURRENT_MPS = 10.0  # the fastest tidal races run at about 10 m/s (Saltstraumen)
MAX_WIND_MPS = 80.0  # above the strongest hurricanes' sustained winds
WindSpeed = Annotated[float, Field(ge=0, le=MAX_WIND_MPS)]
GustStd = Annotated[float, Field(ge=0, le=MAX_WIND_MPS / 4)]


class EnvironmentConfigError(ConfigError):
    """An environment setting (wind zone, current map) is invalid; the message names it."""


class CurrentMapError(EnvironmentConfigError):
    """A current map file is missing, unreadable or has the wrong shape or values."""


class CurrentMapConfig(Strict):
    """A gridded current map: (u, v) water velocity at the nodes of a regular grid.

    `path` is a `.npy` file holding a float array of shape (rows, cols, 2) in m/s, where
    element [j, i] is the velocity at (origin_m.x + i*spacing_m, origin_m.y + j*spacing_m),
    so row 0 is the SOUTH edge; or an 8-bit RGB(A) image (`.png`, ...) read as displayed,
    north up: its bottom-left pixel is the node at `origin_m`, and each channel c in 0..255
    encodes (c - 128) / 127 * scale_mps (R: u east, G: v north; 128 is exactly zero).
    Between nodes the velocity is bilinear; outside the grid it is the nearest edge value
    ("edge") or zero ("zero"). The map adds to the uniform current.
    """

    path: Annotated[str, Field(min_length=1)]
    origin_m: Vec2 = (0.0, 0.0)
    spacing_m: Positive
    scale_mps: Annotated[float, Field(gt=0, le=MAX_CURRENT_MPS)] | None = None
    outside: Literal["edge", "zero"] = "edge"


class CurrentConfig(Strict):
    """Water current: a uniform world-frame vector (m/s, the way the water flows) plus a map."""

    velocity_mps: Vec2 = (0.0, 0.0)
    map: CurrentMapConfig | None = None

    @field_validator("velocity_mps")
    @classmethod
    def _plausible(cls, v: Vec2) -> Vec2:
        if math.hypot(*v) > MAX_CURRENT_MPS:
            raise ValueError(
                f"a current of {math.hypot(*v):g} m/s; at most {MAX_CURRENT_MPS:g} m/s"
            )
        return v


class WindZone(Strict):
    """A region where the wind differs: a circle or a polygon, with its own speed and direction.

    Inside the zone its wind replaces the global wind; where zones overlap, the zone listed
    LAST wins. Polygons are simple (not self-intersecting), given as (x, y) vertices in `map`,
    either orientation, not closed (the last vertex joins the first). `gust_std_mps` of None
    takes the global gust intensity; each zone has its own independent gust process.
    """

    name: str = ""
    shape: Literal["circle", "polygon"]
    center_m: Vec2 | None = None
    radius_m: Positive | None = None
    vertices_m: list[Vec2] | None = None
    speed_mps: WindSpeed
    toward_rad: Angle = 0.0
    gust_std_mps: GustStd | None = None

    @model_validator(mode="after")
    def _shape_fields(self) -> WindZone:
        if self.shape == "circle":
            if self.center_m is None or self.radius_m is None:
                raise ValueError("a circle zone needs center_m and radius_m")
            if self.vertices_m is not None:
                raise ValueError("vertices_m is only for shape 'polygon'")
            return self
        if self.center_m is not None or self.radius_m is not None:
            raise ValueError("center_m and radius_m are only for shape 'circle'")
        _check_polygon(self.vertices_m)
        return self


def _check_polygon(vertices: list[Vec2] | None) -> None:
    """A polygon zone needs >= 3 vertices, a non-zero area and no crossing edges."""
    if vertices is None or len(vertices) < 3:
        got = 0 if vertices is None else len(vertices)
        raise ValueError(f"a polygon zone needs vertices_m with at least 3 points (got {got})")
    crossing = polygon_self_intersects(vertices)  # first: a bow tie's halves cancel in area
    if crossing is not None:
        raise ValueError(f"polygon vertices_m: edges {crossing[0]} and {crossing[1]} cross")
    if abs(polygon_area(vertices)) < 1e-9:
        raise ValueError("polygon vertices_m enclose no area (all points on a line?)")


class WindConfig(Strict):
    """Global wind plus zones; gusts are a first-order Gauss-Markov process per wind source.

    speed_mps / toward_rad: the mean global wind (see the module docstring for the direction
    convention). Gusts add g(t) to the speed along the source's direction, with g stationary,
    zero-mean, standard deviation `gust_std_mps` and autocorrelation exp(-|lag| / tau),
    tau = `gust_time_constant_s` (2 s as in VRX); the speed never goes below zero.
    Air density sets the wind force (0.5 rho_a V^2 A C).
    """

    speed_mps: WindSpeed = 0.0
    toward_rad: Angle = 0.0
    gust_std_mps: GustStd = 0.0
    gust_time_constant_s: Positive = 2.0
    air_density_kg_m3: Positive = 1.225
    zones: list[WindZone] = Field(default_factory=list)

    @property
    def mean_velocity_mps(self) -> Vec2:
        """The global mean wind as a world-frame vector."""
        return (
            self.speed_mps * math.cos(self.toward_rad),
            self.speed_mps * math.sin(self.toward_rad),
        )


class RainConfig(Strict):
    """Rain in force over the whole world: the rate the LiDAR rain model (paper eq. 1) takes,
    within the 0-50 mm/h the original simulator offered."""

    rate_mm_h: Annotated[float, Field(ge=0.0, le=50.0)] = 0.0
