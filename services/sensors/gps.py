"""GPS model: the antenna's `map` (ENU) position, plus noise, as a WGS84 fix.

`method="wgs84"` (default) converts exactly (catabot.world.geo.EnuFrame, < 1 mm). Its altitude
is `altitude="local"` by default: the flat world is a local map, and a fix's altitude is the
origin's plus the antenna's height in `map`, so a boat on the water reads the same altitude
anywhere. `altitude="ellipsoid"` keeps the exact WGS84 height of the flat world, which shows
the Earth's curvature far from the origin (+1.96 m at 5 km, +49 m at 25 km: `map` is the
tangent plane at the origin, d^2 / 2R above the ellipsoid). Latitude and longitude are the
exact conversion's either way. `method="paper_table"` reproduces the original simulator's
eq. (8)-(9) tables, which ignore curvature (errors in the docstring of
catabot.world.geo.paper_table_enu_to_geodetic); its altitude is always local.

Noise is white Gaussian, drawn in metres before the conversion: `horizontal_sigma` on each
of east and north, `vertical_sigma` on up. Defaults 0.5 m and 1.0 m: a good single-band
receiver with SBAS under open sky (vertical error is about twice horizontal, as the
satellites are all above). Real GPS errors are correlated over minutes; a Gauss-Markov
term belongs here when a consumer needs it. The fix reports the sigmas it was drawn with
(zero with `noise=False`), like NavSatFix's covariance.
"""

from __future__ import annotations

from typing import ClassVar, Literal

import numpy as np

from catabot.bus.messages import GpsFix, Message, VesselState
from catabot.config.sensors import GpsParams
from catabot.world import seeding
from catabot.world.geo import EnuFrame, GeoError, paper_table_enu_to_geodetic
from services.sensors.common import (
    SensorError,
    finite_vector,
    rotation_from_quaternion,
)
from services.sensors.mount import Mount

Method = Literal["wgs84", "paper_table"]
METHODS: tuple[Method, ...] = ("wgs84", "paper_table")


class GpsModel:
    """One GPS receiver. Deterministic: the same seed and name give the same fixes."""

    message: ClassVar[type[Message]] = GpsFix

    def __init__(self, params: GpsParams, mount: Mount) -> None:
        origin = mount.origin
        try:
            self.frame = EnuFrame(origin.latitude_deg, origin.longitude_deg, origin.altitude_m)
        except GeoError as exc:
            raise SensorError(f"GPS {mount.name!r} origin: {exc}") from None
        self.method: Method = params.method
        self.local = params.altitude == "local"
        self.horizontal_sigma, self.vertical_sigma = params.horizontal_sigma, params.vertical_sigma
        self.antenna_offset = np.array(params.antenna_offset, dtype=np.float64)
        self.noise, self.name = mount.noise, mount.name
        self._rng = seeding.rng(mount.seed, mount.name)

    @property
    def sigmas(self) -> tuple[float, float]:
        """Horizontal and vertical 1-sigma (m) of the fixes; zero when noise is off."""
        return (self.horizontal_sigma, self.vertical_sigma) if self.noise else (0.0, 0.0)

    def antenna_position(self, state: VesselState) -> np.ndarray:
        """The antenna's position in `map` (m): the body origin plus the rotated offset."""
        rot = rotation_from_quaternion(state.orientation)
        return finite_vector(state.position, "position (m)") + rot @ self.antenna_offset

    def sample(self, state: VesselState, *, tick: int, stamp_ns: int) -> GpsFix:
        """One fix of the antenna at the state's pose."""
        enu = self.antenna_position(state)
        h_sigma, v_sigma = self.sigmas
        if self.noise:
            enu = enu + np.array([h_sigma, h_sigma, v_sigma]) * self._rng.standard_normal(3)
        lat, lon, alt = self.to_geodetic(enu)
        return GpsFix(
            tick=tick,
            stamp_ns=stamp_ns,
            latitude=lat,
            longitude=lon,
            altitude=alt,
            horizontal_sigma=h_sigma,
            vertical_sigma=v_sigma,
        )

    def to_geodetic(self, enu: np.ndarray) -> tuple[float, float, float]:
        """Latitude, longitude (deg), altitude (m) of a `map` position by this GPS's method."""
        f = self.frame
        try:
            if self.method == "wgs84":
                convert = f.to_map_geodetic if self.local else f.to_geodetic
                lat, lon, alt = convert(enu[0], enu[1], enu[2])
            else:
                origin = (f.latitude_deg, f.longitude_deg, f.altitude_m)
                lat, lon, alt = paper_table_enu_to_geodetic(enu[0], enu[1], enu[2], origin=origin)
        except GeoError as exc:
            raise SensorError(
                f"GPS {self.name!r}: position {tuple(enu)} has no fix: {exc}"
            ) from None
        return float(lat), float(lon), float(alt)
