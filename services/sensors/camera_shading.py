"""The camera's colour image, shaded from the same ray hits as depth and segmentation.

Not photorealism: a cheap, deterministic picture whose cues match the labels (a detector
trained on it must find boats by shape and shading, not by a flat colour), costing a few ms
per VGA frame because every step is a vectorised NumPy expression over the hit pixels.
- sky: a gradient from a pale horizon to a blue zenith by the ray's elevation;
- water: a dark blue-green body plus the sky reflected in the wave normal, weighted by
  Schlick's Fresnel term (glancing rays mirror the sky, steep ones see into the water);
- terrain: sand, grass, rock by height, Lambert-shaded from a fixed sun;
- vessels and buoys: one palette colour per instance, Lambert-shaded.
Rain (mm/h) attenuates contrast toward a grey veil with distance, t = exp(-k R^a d)
(extinction grows sub-linearly with rain rate, as in visibility-vs-rain fits), and draws
seeded bright streaks whose count grows with the rate.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from services.sensors.scene import CLASS_BUOY, CLASS_TERRAIN, CLASS_VESSEL, CLASS_WATER

F32 = NDArray[np.float32]

SUN = np.array([0.4, 0.3, 0.85], dtype=np.float32) / np.float32(np.linalg.norm([0.4, 0.3, 0.85]))
HORIZON = np.array([200, 215, 230], dtype=np.float32)
ZENITH = np.array([70, 120, 200], dtype=np.float32)
WATER = np.array([15, 55, 70], dtype=np.float32)
VEIL = np.array([175, 178, 182], dtype=np.float32)
TERRAIN_HEIGHTS = np.array([0.0, 2.0, 4.0, 20.0, 35.0], dtype=np.float32)
TERRAIN_COLORS = np.array(
    [[194, 178, 128], [194, 178, 128], [85, 130, 60], [85, 120, 60], [125, 118, 110]],
    dtype=np.float32,
)
PALETTE = np.array(
    [
        [230, 60, 50], [245, 200, 40], [240, 240, 235], [250, 130, 30], [200, 60, 160],
        [60, 180, 90], [230, 90, 120], [140, 90, 60], [30, 30, 35], [100, 200, 220],
        [180, 40, 40], [250, 160, 120], [120, 120, 220], [200, 200, 80], [80, 80, 80],
        [255, 110, 0],
    ],
    dtype=np.float32,
)  # fmt: skip
RAIN_K_PER_M = 2.0e-4  # extinction at 1 mm/h (1/m): ~0.2 /km, visibility ~20 km
RAIN_EXPONENT = 0.7  # extinction ~ R^0.7: 50 mm/h gives ~3 /km, visibility ~1.3 km
STREAKS_PER_MM_H = 15


def sky(dz: F32) -> F32:
    """Sky colour for rays of world elevation sine `dz` (below the horizon: horizon colour)."""
    t = np.sqrt(np.clip(dz, 0.0, 1.0))[:, None]
    return (HORIZON + t * (ZENITH - HORIZON)).astype(np.float32)


def lambert(normal: F32) -> F32:
    """Ambient plus diffuse light from the fixed sun, (N, 1)."""
    light = 0.35 + 0.65 * np.clip(np.dot(normal, SUN), 0.0, 1.0)
    return light[:, None].astype(np.float32)


def shade(
    cls: NDArray[np.uint8],
    instance: NDArray[np.int32],
    rng: F32,
    normal: F32,
    dirs: F32,
    origin_z: float,
) -> F32:
    """(N, 3) float colours 0..255 of N rays (world directions `dirs`, world hit normals).

    Sky and water, most of a frame, are one pass over every pixel with no gather or
    scatter (a sky pixel is water with Fresnel weight 1 and the unreflected ray); terrain
    and bodies, the few remaining pixels, are gathered, shaded and put back."""
    out = _sky_and_water(cls, normal, dirs)
    for c, fn in ((CLASS_TERRAIN, _terrain), (CLASS_VESSEL, _body), (CLASS_BUOY, _body)):
        idx = np.flatnonzero(cls == c)
        if idx.size:
            out[idx] = fn(idx, instance, rng, normal, dirs, origin_z)
    return out


def _sky_and_water(cls: NDArray[np.uint8], n: F32, d: F32) -> F32:
    """Water: its colour blended with the sky mirrored in the wave normal by Schlick's
    Fresnel term; everything else: the sky along the ray."""
    water = cls == CLASS_WATER
    dot = d[:, 0] * n[:, 0] + d[:, 1] * n[:, 1] + d[:, 2] * n[:, 2]
    grazing = 1.0 - np.clip(-dot, 0.0, 1.0)
    grazing2 = grazing * grazing
    fresnel = np.where(water, 0.02 + 0.98 * grazing2 * grazing2 * grazing, 1.0)
    seen_z = np.where(water, d[:, 2] - 2.0 * dot * n[:, 2], d[:, 2])
    sky_rgb = sky(seen_z.astype(np.float32))
    return (sky_rgb + (1.0 - fresnel[:, None]) * (WATER - sky_rgb)).astype(np.float32)


def _terrain(
    idx: NDArray[np.intp], inst: NDArray[np.int32], r: F32, n: F32, d: F32, z: float
) -> F32:
    height = z + r[idx] * d[idx, 2]
    rgb = np.stack(
        [np.interp(height, TERRAIN_HEIGHTS, TERRAIN_COLORS[:, k]) for k in range(3)], axis=1
    )
    return (rgb * lambert(n[idx])).astype(np.float32)


def _body(idx: NDArray[np.intp], inst: NDArray[np.int32], r: F32, n: F32, d: F32, z: float) -> F32:
    return PALETTE[inst[idx] % len(PALETTE)] * lambert(n[idx])


def rain_veil(color: F32, distance: F32, rate_mm_h: float) -> F32:
    """Blend (N, 3) colours toward the grey veil by exp(-k R^a d); no-op without rain."""
    if rate_mm_h <= 0.0:
        return color
    beta = RAIN_K_PER_M * rate_mm_h**RAIN_EXPONENT
    t = np.exp(-beta * distance)[:, None].astype(np.float32)
    return t * color + (1.0 - t) * VEIL


def rain_streaks(image: F32, rate_mm_h: float, rng: np.random.Generator) -> None:
    """Brighten short, slanted streaks in an (H, W, 3) image, in place (seeded, no loops)."""
    count = int(rate_mm_h * STREAKS_PER_MM_H)
    if count <= 0:
        return
    h, w = image.shape[:2]
    start = rng.random((count, 2)) * (h, w)
    length = rng.integers(6, 20, size=count)
    steps = np.arange(20)
    rows = (start[:, :1] + steps).astype(np.intp)
    cols = (start[:, 1:] + 0.25 * steps).astype(np.intp)
    ok = (steps < length[:, None]) & (rows < h) & (cols < w)
    rows, cols = rows[ok], cols[ok]
    image[rows, cols] = 0.7 * image[rows, cols] + 0.3 * np.float32(235.0)
