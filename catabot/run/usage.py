"""What each process of a run cost: CPU seconds of its stepping loop and its peak memory.

Each service writes `log/<name>.usage.json` when its loop ends; the conductor puts its own in
its result line and `catabot run` adds its own, so `log/run.json` has one table of every
process (the Table II benchmark prints it). Peak resident memory is the kernel's high-water
mark, so it catches a spike a sampler would miss and costs nothing while the run goes: the
process's own (VmHWM), not getrusage's ru_maxrss, which a process started by fork and exec
inherits from its parent (`catabot run` launched from a 1 GB test session reported 1 GB).

Resident memory counts every page of a shared library that the process has mapped, in each
process that maps it, and how many pages a fault maps depends on the page cache: on Linux
6.18 (ext4 with large folios) a library freshly written by pip is cached in large folios and a
fault maps a whole one, so right after `make setup` llvmlite's library alone was 106 MiB
resident in each process that imports numba, 36 MiB once the cache had been dropped and
re-read. So each process also reports, as its loop ends, its proportional share (PSS: a
shared page split between the processes that map it) and its anonymous memory (what it
allocated itself: heaps, arrays, compiled code), which do not depend on that.
"""

from __future__ import annotations

import contextlib
import json
import resource
from collections.abc import Iterable
from pathlib import Path

KIB_PER_MB = 1024.0
PEAK, PSS, ANON = "peak_rss_mb", "pss_mb", "anon_mb"  # run.json's memory tables, MiB
MEMORY = (PEAK, PSS, ANON)


def peak_rss_mb() -> float:
    """This process's peak resident set size so far, in MiB (Linux reports KiB); where there
    is no /proc, getrusage's figure."""
    with contextlib.suppress(OSError, StopIteration, ValueError, IndexError):
        status = Path("/proc/self/status").read_text().splitlines()
        kib = next(line.split()[1] for line in status if line.startswith("VmHWM:"))
        return round(int(kib) / KIB_PER_MB, 1)
    return round(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / KIB_PER_MB, 1)


def memory_mb() -> dict[str, float]:
    """`MEMORY` of this process now, MiB: the peak always, PSS and anonymous memory where
    the kernel reports them (/proc/self/smaps_rollup, Linux 4.14 on)."""
    out = {PEAK: peak_rss_mb()}
    with contextlib.suppress(OSError, ValueError, KeyError, IndexError):
        kib = dict(_kib_fields(Path("/proc/self/smaps_rollup").read_text()))
        out |= {PSS: kib["Pss"] / KIB_PER_MB, ANON: kib["Anonymous"] / KIB_PER_MB}
    return {k: round(v, 1) for k, v in out.items()}


def _kib_fields(text: str) -> Iterable[tuple[str, int]]:
    """`Name:   123 kB` lines as (name, 123)."""
    for line in text.splitlines():
        name, _, rest = line.partition(":")
        if rest.strip().endswith("kB"):
            yield name, int(rest.split()[0])


def write_usage(name: str, run_dir: Path, cpu_s: float) -> None:
    """CPU seconds of the stepping loop (every thread, start-up excluded) and memory."""
    (run_dir / "log").mkdir(parents=True, exist_ok=True)
    record = {"cpu_s": round(cpu_s, 3), **memory_mb()}
    (run_dir / "log" / f"{name}.usage.json").write_text(json.dumps(record))


def read_usage(run_dir: Path, names: Iterable[str], field: str) -> dict[str, float]:
    """One field of each process's usage file, where it was written (a crashed service
    writes none)."""
    out: dict[str, float] = {}
    for name in names:
        path = run_dir / "log" / f"{name}.usage.json"
        with contextlib.suppress(OSError, ValueError, KeyError, TypeError):
            out[name] = float(json.loads(path.read_text())[field])
    return out
