"""Regenerate catabot/data/terrain/bay.png: a 600 m synthetic bay (2 m/px, -15..25 m).

A sloping north shore, an island, and a shallow bank: enough to ground a boat and to see
terrain in sensors, small enough to ship (the real New York image lives in ../shared).
"""

from pathlib import Path

import numpy as np
from PIL import Image

N, PX, LO, HI = 300, 2.0, -15.0, 25.0
y, x = np.mgrid[N - 1 : -1 : -1, 0:N] * PX + PX / 2  # row 0 is the north edge
shore = -12.0 + 37.0 * np.clip((y - 420.0) / 140.0, 0.0, 1.0)
island = -12.0 + 36.0 * np.exp(-((x - 420.0) ** 2 + (y - 250.0) ** 2) / (2 * 28.0**2))
bank = -12.0 + 10.0 * np.exp(
    -((x - 150.0) ** 2) / (2 * 40.0**2) - ((y - 150.0) ** 2) / (2 * 60.0**2)
)
height = np.maximum.reduce([shore, island, bank])
pixels = np.round((height - LO) / (HI - LO) * 255).clip(0, 255).astype(np.uint8)
out = Path(__file__).resolve().parents[1] / "catabot" / "data" / "terrain" / "bay.png"
Image.fromarray(pixels, mode="L").save(out, optimize=True)
print(out, pixels.shape, out.stat().st_size, "bytes")
