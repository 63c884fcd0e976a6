"""The NumPy COCO RLE encoder gives pycocotools' bytes, and decodes back to the mask."""

from __future__ import annotations

import numpy as np
import pytest
from pycocotools import mask as coco_mask

from services.datasets import rle

pytestmark = pytest.mark.filterwarnings("ignore:__array__ implementation:DeprecationWarning")


def _masks() -> list[np.ndarray]:
    rng = np.random.default_rng(5)
    blob = np.zeros((40, 60), bool)
    blob[10:25, 5:50] = True
    blob[12:14, 20:30] = False  # a hole: more runs
    corner = np.zeros((7, 9), bool)
    corner[0, 0] = True  # starts with a 1: an empty first run of 0s
    big = np.zeros((480, 640), bool)
    big[100:400, 300:620] = rng.random((300, 320)) < 0.97  # long runs and differences < 0
    return [
        blob,
        corner,
        big,
        np.zeros((5, 5), bool),
        np.ones((3, 4), bool),
        rng.random((33, 17)) < 0.5,
    ]


@pytest.mark.parametrize("mask", _masks())
def test_same_string_as_pycocotools_and_decodes_back(mask: np.ndarray) -> None:
    ours = rle.encode(mask)
    theirs = coco_mask.encode(np.asfortranarray(mask.astype(np.uint8)))
    assert ours["counts"] == theirs["counts"].decode() and ours["size"] == list(theirs["size"])
    back = coco_mask.decode({"size": ours["size"], "counts": ours["counts"].encode()})
    assert (back.astype(bool) == mask).all()
    assert coco_mask.area(theirs) == mask.sum()


def test_runs_count_column_major_from_a_run_of_zeros() -> None:
    mask = np.array([[1, 0], [1, 1]], bool)  # column-major: 1 1 0 1
    assert rle.runs(mask) == [0, 2, 1, 1]
