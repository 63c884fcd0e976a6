"""The camera's colour image, shaded from the same ray hits as depth and segmentation.

Not photorealism: a cheap, deterministic picture whose cues match the labels (a detector
trained on it must find boats by shape and shading, not by a flat colour), costing a few ms
per VGA frame because every step is a vectorised NumPy expression over the hit pixels.
- sky: a gradient from a pale horizon to a blue zenith by the ray's elevation;
- water: a dark blue-green body plus the sky reflected in the wave normal, weighted by
  Schlick's Fresnel term (glancing rays mirror the sky, steep ones see into the water);
- terrain: sand, grass, rock by height, Lambert-shaded from a fixed sun;
- vessels and buoys: one palette colour per instance (buoys: a mark's), Lambert-shaded.
Rain (mm/h) attenuates contrast toward a grey veil with distance, t = exp(-k R^a d)
(extinction grows sub-linearly with rain rate, as in visibility-vs-rain fits), and draws
seeded bright streaks whose count grows with the rate.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from catabot.bus.messages import CLASS_BUOY, CLASS_TERRAIN, CLASS_VESSEL, CLASS_WATER

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
BUOY_PALETTE = np.array(  # IALA marks: lateral red and green, special yellow, and orange;
    [[200, 30, 30], [30, 150, 60], [250, 200, 30], [255, 120, 0]],  # the vessels' palette
    dtype=np.float32,  # drew some buoys teal or grey, lost against the water (a trial user)
)  # fmt: skip
RAIN_K_PER_M = 2.0e-4  # extinction at 1 mm/h (1/m): ~0.2 /km, visibility ~20 km
RAIN_EXPONENT = 0.7  # extinction ~ R^0.7: 50 mm/h gives ~3 /km, visibility ~1.3 km
STREAKS_PER_MM_H = 15


def sky(dz: F32) -> F32:
    """(3, N) sky colour planes for rays of world elevation sine `dz` (below the horizon:
    horizon colour)."""
    t = np.sqrt(np.clip(dz, 0.0, 1.0))
    return HORIZON[:, None] + t * (ZENITH - HORIZON)[:, None]


def lambert(normal: F32) -> F32:
    """Ambient plus diffuse light from the fixed sun, (N,)."""
    light: F32 = 0.35 + 0.65 * np.clip(np.dot(normal, SUN), 0.0, 1.0)
    return light


def shade(
    cls: NDArray[np.uint8],
    instance: NDArray[np.int32],
    rng: F32,
    normal: F32,
    dirs: F32,
    origin_z: float,
) -> F32:
    """(3, N) float colour planes 0..255 of N rays (world directions `dirs`, world hit
    normals). Planes, not (N, 3) pixels: NumPy runs an (N, 3) expression as N loops of 3,
    several times slower than 3 loops of N.

    The sky is one pass over every pixel with no gather; water, terrain and bodies are
    gathered (np.take), shaded and put back over it."""
    out = _sky_and_water(cls, normal, dirs)
    for c, fn in ((CLASS_TERRAIN, _terrain), (CLASS_VESSEL, _body), (CLASS_BUOY, _buoy)):
        idx = np.flatnonzero(cls == c)
        if idx.size:
            out[:, idx] = fn(idx, instance, rng, normal, dirs, origin_z)
    return out


def _sky_and_water(cls: NDArray[np.uint8], n: F32, d: F32) -> F32:
    """Everything: the sky along the ray; then the water (about half a frame) only: its
    colour blended with the sky mirrored in the wave normal by Schlick's Fresnel term."""
    out = sky(d[:, 2])
    idx = np.flatnonzero(cls == CLASS_WATER)
    if idx.size == 0:
        return out
    nw, dw = np.take(n, idx, axis=0), np.take(d, idx, axis=0)  # rows: faster than columns
    dot = dw[:, 0] * nw[:, 0] + dw[:, 1] * nw[:, 1] + dw[:, 2] * nw[:, 2]
    grazing = 1.0 - np.clip(-dot, 0.0, 1.0)
    grazing2 = grazing * grazing
    fresnel = 0.02 + 0.98 * grazing2 * grazing2 * grazing
    mirrored = sky((dw[:, 2] - 2.0 * dot * nw[:, 2]).astype(np.float32))
    mirrored += (1.0 - fresnel) * (WATER[:, None] - mirrored)
    out[:, idx] = mirrored
    return out


def _terrain(
    idx: NDArray[np.intp], inst: NDArray[np.int32], r: F32, n: F32, d: F32, z: float
) -> F32:
    height = z + np.take(r, idx) * np.take(d[:, 2], idx)
    rgb = np.stack([np.interp(height, TERRAIN_HEIGHTS, TERRAIN_COLORS[:, k]) for k in range(3)])
    return (rgb * lambert(np.take(n, idx, axis=0))).astype(np.float32)


def _body(idx: NDArray[np.intp], inst: NDArray[np.int32], r: F32, n: F32, d: F32, z: float) -> F32:
    return _painted(PALETTE, idx, inst, n)


def _buoy(idx: NDArray[np.intp], inst: NDArray[np.int32], r: F32, n: F32, d: F32, z: float) -> F32:
    return _painted(BUOY_PALETTE, idx, inst, n)


def _painted(palette: F32, idx: NDArray[np.intp], inst: NDArray[np.int32], n: F32) -> F32:
    """A palette colour per instance, Lambert-shaded."""
    colour: F32 = palette.T[:, np.take(inst, idx) % len(palette)]
    return colour * lambert(np.take(n, idx, axis=0))


def rain_veil(color: F32, distance: F32, rate_mm_h: float) -> F32:
    """Blend (3, N) colour planes toward the grey veil by exp(-k R^a d); no-op without rain."""
    if rate_mm_h <= 0.0:
        return color
    beta = RAIN_K_PER_M * rate_mm_h**RAIN_EXPONENT
    t = np.exp(-beta * distance).astype(np.float32)
    return t * color + (1.0 - t) * VEIL[:, None]


def rain_streaks(image: F32, rate_mm_h: float, rng: np.random.Generator) -> None:
    """Brighten short, slanted streaks in (3, H, W) colour planes, in place (seeded, no
    loops)."""
    count = int(rate_mm_h * STREAKS_PER_MM_H)
    if count <= 0:
        return
    h, w = image.shape[1:]
    start = rng.random((count, 2)) * (h, w)
    length = rng.integers(6, 20, size=count)
    steps = np.arange(20)
    rows = (start[:, :1] + steps).astype(np.intp)
    cols = (start[:, 1:] + 0.25 * steps).astype(np.intp)
    ok = (steps < length[:, None]) & (rows < h) & (cols < w)
    rows, cols = rows[ok], cols[ok]
    image[:, rows, cols] = 0.7 * image[:, rows, cols] + 0.3 * np.float32(235.0)
