"""NumPy's OpenBLAS on one thread: every CataBot process calls this at start."""

from __future__ import annotations

import ctypes


def single_thread_blas() -> bool:
    """Run NumPy's OpenBLAS on one thread in this process; True if it could.

    Why: the services' products are (N, 3) arrays times 3 x 3 matrices, which OpenBLAS
    splits over its threads; those threads then spin waiting for more work and, with five
    processes on a 2-core machine, take the cores the other services step on (a 640 x 480
    camera cast went from 13 ms to 20 ms). One thread gives the same bits and no spinning.
    The library is found among the process's mappings (Linux); elsewhere this is a no-op.
    """
    try:
        with open("/proc/self/maps", encoding="utf-8") as maps:
            paths = sorted({ln.split()[-1] for ln in maps if "openblas" in ln.lower()})
    except OSError:
        return False
    done = False
    for path in paths:
        lib = ctypes.CDLL(path)
        for name in OPENBLAS_SET_THREADS:
            setter = getattr(lib, name, None)
            if setter is not None:
                setter(ctypes.c_int(1))
                done = True
                break
    return done


OPENBLAS_SET_THREADS = (
    "scipy_openblas_set_num_threads64_",  # NumPy's own wheels (64-bit ints, renamed)
    "scipy_openblas_set_num_threads",
    "openblas_set_num_threads64_",
    "openblas_set_num_threads",
)
