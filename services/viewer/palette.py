"""Colours of the viewer, computed array-wide: classes, LiDAR intensity, terrain height.

LiDAR points are coloured by intensity on a perceptual ramp and rain returns in magenta, as
the paper's Fig. 5 separates them; the terrain by height, water-blue below the surface and
green to brown to grey above (an elevation map's usual tints), so shores read at a glance.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from catabot.bus.messages import LABEL_CLASSES
from catabot.world.label_colors import CLASS_COLORS
from catabot.world.label_colors import RAIN_COLOR as RAIN

U8 = NDArray[np.uint8]
EGO = (255, 140, 0)  # scenario vessels
BOAT = (230, 230, 235)  # traffic boats
BUOY = CLASS_COLORS["buoy"]
WATER = (30, 90, 160, 255)
RADAR = (60, 255, 90)


def class_table() -> list[tuple[int, str, tuple[int, int, int]]]:
    """(id, name, colour) of every label class: the annotation context of images and boxes."""
    return [(i, name, CLASS_COLORS[name]) for i, name in enumerate(LABEL_CLASSES)]


def _ramp(t: NDArray[np.floating], stops: NDArray[np.float64]) -> U8:
    """Piecewise-linear colours of t in [0, 1] through `stops` (k, 3) evenly spaced."""
    x = np.linspace(0.0, 1.0, len(stops))
    t = np.clip(np.nan_to_num(t, nan=0.0), 0.0, 1.0)
    rgb = np.stack([np.interp(t, x, stops[:, c]) for c in range(3)], axis=-1)
    return np.rint(rgb).astype(np.uint8)


_INTENSITY = np.array([[48, 18, 59], [50, 120, 230], [30, 210, 170], [180, 230, 50],
                       [250, 170, 30], [200, 40, 20]], dtype=np.float64)  # fmt: skip
_LAND = np.array([[70, 150, 70], [150, 160, 80], [140, 110, 70], [200, 200, 200]], np.float64)
_SEA = np.array([[10, 30, 90], [40, 110, 190], [150, 210, 230]], np.float64)


def intensity_colors(intensity: NDArray[np.floating], is_rain: NDArray[np.bool_]) -> U8:
    """(N, 3) colours: log intensity on the ramp (returns span decades), rain in magenta."""
    logi = np.log10(np.maximum(np.asarray(intensity, dtype=np.float64), 1e-12))
    finite = logi[np.asarray(~is_rain)]
    lo, hi = np.percentile(finite, [2, 98]) if finite.size else (0.0, 1.0)
    colors = _ramp((logi - lo) / max(hi - lo, 1e-9), _INTENSITY)
    colors[np.asarray(is_rain)] = RAIN
    return colors


def terrain_colors(height_m: NDArray[np.floating], low_m: float, high_m: float) -> U8:
    """(N, 3) colours by height: the sea ramp from `low_m` to 0, the land ramp from 0 up."""
    h = np.asarray(height_m, dtype=np.float64)
    sea = _ramp(1.0 - h / min(low_m, -1e-6), _SEA)
    land = _ramp(h / max(high_m, 1e-6), _LAND)
    return np.where((h < 0)[:, None], sea, land).astype(np.uint8)


def radar_colors(strength: NDArray[np.integer]) -> U8:
    """(N, 3) radar-screen green, brighter for a stronger echo (uint8 strength)."""
    t = np.asarray(strength, dtype=np.float64)[:, None] / 255.0
    return np.rint(np.array(RADAR) * (0.35 + 0.65 * t)).astype(np.uint8)
