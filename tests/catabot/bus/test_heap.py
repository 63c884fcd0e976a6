"""The kept heap (catabot/bus/heap.py): a stepping loop's big temporaries stop costing page
faults once the process has tuned malloc, as every CataBot process does at start."""

from __future__ import annotations

import platform
import subprocess
import sys

import pytest

LOOP = """
import resource, sys
import numpy as np
from catabot.bus.heap import keep_heap
if sys.argv[1] == "kept":
    assert keep_heap()
x = np.ones((5, 100_000))
rows = np.array([0, 0, 1, 0, 1, 2, 0, 1, 2, 3, 0, 1, 2, 3, 4])
for _ in range(5):
    x[rows] * x[rows]  # warm up: the heap grows once
before = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
for _ in range(50):
    x[rows] * x[rows]  # three 12 MB temporaries alive at once, as in a camera cast
print(resource.getrusage(resource.RUSAGE_SELF).ru_minflt - before)
"""


def faults(mode: str) -> int:
    out = subprocess.run(
        [sys.executable, "-c", LOOP, mode], capture_output=True, text=True, check=True
    )
    return int(out.stdout)


@pytest.mark.skipif(platform.libc_ver()[0] != "glibc", reason="tunes glibc's malloc only")
def test_a_kept_heap_reuses_freed_arrays_instead_of_faulting_pages_in() -> None:
    default, kept = faults("default"), faults("kept")
    assert default > 5_000  # hundreds of fresh pages a loop, zeroed by the kernel each time
    assert kept < 200, (default, kept)  # none, once the heap has grown
