"""The radar's plan position indicator (the paper's minimap): a NORTH-UP Cartesian image of
the latest sweeps, centred on the own vessel, where every return fades linearly to nothing
over `fade_s` seconds after the antenna last painted it.

Each echo cell (beam, range bin) is painted at `fill` azimuths across its beam spacing so
that the far end of adjacent beams (3 m apart at 250 m for 0.75 deg) leaves no gaps between
pixels; it is a scatter of the nonzero cells only, so an empty sea costs nothing. The image
keeps, per pixel, the last painted strength and stamp; `render(stamp_ns)` applies the fade.
Row 0 is north, column 0 west; the own vessel is at the centre.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from catabot.bus.clock import NS_PER_S
from catabot.bus.messages import RadarSweep


class Ppi:
    """Accumulates RadarSweep messages into a fading north-up image of size x size pixels."""

    def __init__(
        self, *, size_px: int, range_m: float, fade_s: float, beam_step_rad: float, fill: int = 4
    ) -> None:
        self.size, self.range_m, self.fade_s = size_px, range_m, fade_s
        self.beam_step = beam_step_rad
        self.fill = np.arange(fill) / fill - 0.5
        self.strength = np.zeros((size_px, size_px), dtype=np.uint8)
        self.painted_s = np.full((size_px, size_px), -np.inf)

    def add(self, sweep: RadarSweep) -> None:
        """Paint the sweep's nonzero cells at its stamp (later sweeps overwrite)."""
        beam, cell = np.nonzero(sweep.intensity)
        if beam.size == 0:
            return
        bins = sweep.intensity.shape[1]
        r = (cell + 0.5) * (sweep.range_m / bins)
        azimuth = sweep.azimuth_start_rad - self.beam_step * beam
        bearing = sweep.heading_rad + azimuth[:, None] + self.beam_step * self.fill[None, :]
        scale = self.size / (2.0 * self.range_m)
        col = (self.size / 2 + r[:, None] * np.cos(bearing) * scale).astype(np.intp)
        row = (self.size / 2 - r[:, None] * np.sin(bearing) * scale).astype(np.intp)
        inside = (col >= 0) & (col < self.size) & (row >= 0) & (row < self.size)
        value = np.broadcast_to(sweep.intensity[beam, cell][:, None], col.shape)
        row, col, value = row[inside], col[inside], value[inside]
        self.strength[row, col] = value
        self.painted_s[row, col] = sweep.stamp_ns / NS_PER_S

    def render(self, stamp_ns: int) -> NDArray[np.uint8]:
        """The image at `stamp_ns`: strength x (1 - age / fade_s), clipped to [0, 1]."""
        age = stamp_ns / NS_PER_S - self.painted_s
        fade = np.clip(1.0 - age / self.fade_s, 0.0, 1.0)
        return np.rint(self.strength * fade).astype(np.uint8)
