"""Run the benchmarks named on the command line (all when none is named)."""

from __future__ import annotations

import importlib
import sys

BENCHMARKS = {
    "lockstep": "benchmarks.lockstep",
    "physics": "benchmarks.physics",
    "sensors": "benchmarks.sensors",
    "cameras": "benchmarks.cameras",
    "table2": "benchmarks.table2",
    "ros": "benchmarks.ros",
    "viewer": "benchmarks.viewer",
    "shards": "benchmarks.shards",
    "recording": "benchmarks.recording",
    "gym": "benchmarks.gym",
    "metrics": "benchmarks.metrics",
}


def main(argv: list[str]) -> int:
    names = argv or list(BENCHMARKS)
    unknown = [n for n in names if n not in BENCHMARKS]
    if unknown:
        print(f"unknown benchmark(s) {unknown}; known: {', '.join(BENCHMARKS)}", file=sys.stderr)
        return 2
    for name in names:
        importlib.import_module(BENCHMARKS[name]).main()
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
