"""COCO run-length encoding of binary masks, with NumPy (no pycocotools at run time).

COCO's RLE counts alternate runs of 0s and 1s over the mask in column-major order, starting
with a (possibly empty) run of 0s; the compressed form packs each count, as the difference
from the count two before it (after the first two), into 5-bit groups of printable
characters (pycocotools' `rleToString`). The runs come from one `diff` over the mask; only
the packing loops, once per run, never per pixel.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray


def runs(mask: NDArray[np.bool_]) -> list[int]:
    """Run lengths of the column-major mask, the first a run of 0s (0 if it starts with 1)."""
    flat = np.asarray(mask, dtype=bool).ravel(order="F")
    if flat.size == 0:
        return []
    edges = np.flatnonzero(flat[1:] != flat[:-1]) + 1
    bounds = np.concatenate([[0], edges, [flat.size]])
    lengths = np.diff(bounds).tolist()
    return [0, *lengths] if flat[0] else lengths


def pack(counts: list[int]) -> str:
    """pycocotools' compressed string of run lengths."""
    out: list[str] = []
    for i, count in enumerate(counts):
        x = count - counts[i - 2] if i > 2 else count
        more = True
        while more:
            c = x & 0x1F
            x >>= 5  # arithmetic shift: negative differences end at -1
            more = x != -1 if c & 0x10 else x != 0
            out.append(chr((c | 0x20 if more else c) + 48))
    return "".join(out)


def encode(mask: NDArray[np.bool_]) -> dict[str, Any]:
    """A COCO compressed RLE `{"size": [h, w], "counts": str}` of a 2-D mask."""
    h, w = mask.shape
    return {"size": [int(h), int(w)], "counts": pack(runs(mask))}
