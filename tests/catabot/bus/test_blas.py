"""One OpenBLAS thread: found and set in NumPy's own library, results unchanged."""

from __future__ import annotations

import sys

import numpy as np
import pytest

from catabot.bus.blas import single_thread_blas


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc/self/maps")
def test_numpy_openblas_goes_to_one_thread_with_the_same_bits() -> None:
    rng = np.random.default_rng(0)
    a, b = rng.normal(size=(5000, 3)), rng.normal(size=(3, 3))
    before = a @ b
    assert single_thread_blas()
    assert np.array_equal(a @ b, before)
