"""A heap that keeps what it got: every CataBot process calls this at start, with BLAS's.

Why: a service makes the same large temporaries every tick. With several alive at once,
glibc by default maps them fresh or trims the heap's top when they are freed and grows it
again for the next, and the kernel zeroes every page on first touch: measured, a 640 x 480
camera frame took 42 ms, 32 ms with the heap kept (benchmarks.cameras), and a physics wave
evaluation of 0.8 MB temporaries 1.19 ms, 0.28 ms kept. Raising the mmap and trim
thresholds lets freed blocks be reused, within the process's own peak memory (which the
run reports: it does not grow).
"""

from __future__ import annotations

import ctypes
import ctypes.util

M_TRIM_THRESHOLD = -1  # glibc's mallopt parameters (malloc.h)
M_TOP_PAD = -2
M_MMAP_THRESHOLD = -3
MMAP_THRESHOLD_B = 64 * 2**20  # blocks up to this come from the heap and are reused
TRIM_THRESHOLD_B = 256 * 2**20  # free memory kept at the heap's top before it shrinks
TOP_PAD_B = 16 * 2**20  # grow the heap by this much more than asked: fewer brk calls


def keep_heap() -> bool:
    """Tune glibc's malloc for a stepping loop; True if it could (False off glibc)."""
    name = ctypes.util.find_library("c")
    if name is None:
        return False
    try:
        mallopt = ctypes.CDLL(name).mallopt
    except (OSError, AttributeError):  # not glibc (musl, macOS): nothing to tune
        return False
    settings = (
        (M_MMAP_THRESHOLD, MMAP_THRESHOLD_B),
        (M_TRIM_THRESHOLD, TRIM_THRESHOLD_B),
        (M_TOP_PAD, TOP_PAD_B),
    )
    return all(mallopt(ctypes.c_int(p), ctypes.c_int(v)) == 1 for p, v in settings)
