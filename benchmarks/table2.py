"""The paper's Table II on this machine: the full stack with 0-100 traffic boats.

Each cell is one `catabot run --quiet` (real processes, the recorder on): physics at
100 Hz, the ego with a 32 x 512 LiDAR at 10 Hz in rain, a radar, an IMU at 100 Hz and a
GPS, plus N traffic boats; then with a segmentation camera, then with all four camera
outputs. The boats circle, the original's default (`boatControlType` "Circles"); a last
row runs 100 boats half of them on waypoint paths, with a floating buoy at each of their
waypoints (275 with seed 1). It prints the real-time factor and LiDAR scans per wall-clock
second (from each run's log/run.json) beside the paper's frames per second. The paper's
FPS is the Unity frame rate; our nearest figure is the LiDAR scan rate, and the real-time
factor says whether the run kept up with the clock at all. Sensor types not registered in
catabot/sensor_types.py are left out, and the table says which.

Every service costs more per tick later in a run than in its first seconds (heaps grow,
boats spread), so a cell is 60 simulated seconds by default: steady state, not the start.
The 0-boat cell is the reference every ratio divides by, printed beside it; the memory table
gives each process's peak resident memory (the kernel's high-water mark, log/run.json).
A shared machine's speed drifts between cells, so the target ratios are measured in rounds:
the table's cells are the first, then the 0-boat, 100-boat and waypoint cells (no
perception) run again in turn; each round's ratios divide by that round's 0-boat cell, and
the median over rounds is what meets a target or not.

Usage: python -m benchmarks.table2 [seconds] [--columns 0,1,2] [--boats 0,100] [--rounds 3]
(simulated seconds per cell, default 60), or `python -m benchmarks table2`.
"""

from __future__ import annotations

import json
import math
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import Any

from catabot.config.load import parse_scenario
from catabot.config.sensors import SENSOR_TYPES
from catabot.run.usage import ANON, PEAK, PSS
from catabot.world.world import World

BOATS = (0, 5, 10, 20, 50, 100)
LIDAR_HZ = 10.0
PAPER = {  # Table II: FPS without perception / segmentation recording / four outputs
    0: (55, 33, 15), 5: (54, 32, 14.5), 10: (52, 30, 14),
    20: (51, 29, 13.5), 50: (36, 28, 13), 100: (32, 24, 12),
}  # fmt: skip
COLUMNS = ("no perception", "segmentation", "four outputs")
CIRCLES = {"circle": 1.0}
MIX = {"circle": 0.5, "waypoints": 0.5}


def sensors(column: int) -> list[dict[str, Any]]:
    """The ego's sensors for a column, registered types only."""
    out = [
        {"name": "lidar", "type": "lidar", "rate_hz": LIDAR_HZ},
        {"name": "radar", "type": "radar", "rate_hz": 10.0},
        {"name": "imu", "type": "imu", "rate_hz": 100.0},
        {"name": "gps", "type": "gps", "rate_hz": 10.0},
    ]
    if column > 0:
        only_seg = {"color": False, "depth": False, "normals": False, "segmentation": True}
        outputs = only_seg if column == 1 else {}
        out.append(
            {"name": "camera", "type": "camera", "rate_hz": 10.0, "params": {"outputs": outputs}}
        )
    return [s for s in out if s["type"] in SENSOR_TYPES]


def scenario(
    boats: int, column: int, seconds: float, mix: dict[str, float] = CIRCLES
) -> dict[str, Any]:
    return {
        "name": f"table2_{boats}_{column}_{len(mix)}",
        "seed": 1,
        "duration_s": seconds,
        "rain": {"rate_mm_h": 10.0},
        "vessels": [{"id": "ego", "pose": {"x_m": 0.0, "y_m": 0.0}, "sensors": sensors(column)}],
        "traffic": {"count": boats, "behaviour_mix": mix},
    }


def buoys(seconds: float) -> int:
    """The waypoint buoys of the last row, as the traffic plan places them."""
    return len(World.resolve(parse_scenario(scenario(100, 0, seconds, MIX))).traffic.buoys)


def run_once(data: dict[str, Any], folder: Path) -> dict[str, Any]:
    """One real run; its log/run.json (wall and simulated seconds, how it ended)."""
    path = folder / f"{data['name']}.json"
    path.write_text(json.dumps(data))
    out = folder / data["name"]
    proc = subprocess.run(
        [sys.executable, "-m", "catabot", "run", str(path), "--quiet", "--out", str(out)],
        capture_output=True,
        text=True,
    )
    runs = sorted(out.glob("*/log/run.json"))
    if proc.returncode != 0 or not runs:
        return {"error": (proc.stderr.strip().splitlines() or ["no run.json"])[-1]}
    result: dict[str, Any] = json.loads(runs[-1].read_text())
    return result


def cell(result: dict[str, Any], has_lidar: bool) -> str:
    if result.get("error") or not result.get("wall_s"):
        return f"failed: {str(result.get('error'))[:40]}"
    rtf = result["sim_s"] / result["wall_s"]
    scans = f"{rtf * LIDAR_HZ:5.1f} scans/s" if has_lidar else "   (no lidar)"
    return f"RTF {rtf:5.2f} {scans}"


def cpu_per_tick(result: dict[str, Any]) -> str:
    """Where the time goes: ms of CPU per tick per service (all its threads)."""
    ticks = max(int(result.get("ticks", 0)), 1)
    cpu = result.get("cpu_s") or {}
    return ", ".join(f"{name} {1e3 * s / ticks:.2f} ms" for name, s in cpu.items()) or "n/a"


def option(args: list[str], flag: str, default: list[int]) -> list[int]:
    """A comma-separated list of integers after `flag` (the rows or columns to run)."""
    if flag not in args:
        return default
    return [int(x) for x in args[args.index(flag) + 1].split(",")]


FLAGS = ("--columns", "--boats", "--rounds")
USAGE = __doc__.split("Usage: ")[1].strip() if __doc__ else ""


def main(argv: list[str] | None = None) -> None:
    args = sys.argv[1:] if argv is None else argv
    unknown = [a for a in args if a.startswith("-") and a not in FLAGS]
    if unknown:  # -h included: a typo must not start a 20-minute benchmark
        sys.exit(f"{' '.join(unknown)}: not an option\nusage: {USAGE}")
    numbers = [a for a in args if a.replace(".", "", 1).isdigit()]
    seconds = float(numbers[0]) if numbers and args.index(numbers[0]) == 0 else 60.0
    missing = sorted({"lidar", "radar", "camera"} - set(SENSOR_TYPES))
    columns = option(args, "--columns", [0] if "camera" not in SENSOR_TYPES else [0, 1, 2])
    boats_rows = option(args, "--boats", list(BOATS))
    print(f"Table II: {seconds:g} s simulated per run, recorder on, rain 10 mm/h")
    if missing:
        print(f"  sensor types not registered, left out: {', '.join(missing)}")
    if "camera" not in SENSOR_TYPES:
        print("  columns skipped (no camera): " + ", ".join(COLUMNS[1:]))
    has_lidar = "lidar" in SENSOR_TYPES
    usage: dict[str, str] = {}
    memory: dict[str, str] = {}
    rtf: dict[str, list[float]] = {}
    with tempfile.TemporaryDirectory(prefix="table2-") as tmp:
        rows = [(b, CIRCLES) for b in BOATS if b in boats_rows]
        for boats, mix in rows + ([(100, MIX)] if 100 in boats_rows else []):
            label = f"{boats:4d} boats" + (
                f" (half on waypoints, {buoys(seconds)} buoys)" if mix is MIX else ""
            )
            row = [label]
            for column in columns:
                result = run_once(scenario(boats, column, seconds, mix), Path(tmp))
                row.append(f"{COLUMNS[column]}: {cell(result, has_lidar)} "
                           f"(paper {PAPER[boats][column]} FPS)")  # fmt: skip
                if column == 0:
                    usage[label], memory[label] = cpu_per_tick(result), peak_memory(result)
                    keep_rtf(rtf, row_key(boats, mix), result)
            print(" | ".join(row), flush=True)
        for _ in range(option(args, "--rounds", [3])[0] - 1):
            more_rounds(rtf, seconds, Path(tmp))
    print_ratios(rtf)
    print("CPU per tick in each service's stepping loop (no perception column):")
    for label, text in usage.items():
        print(f"  {label}: {text}")
    print("Peak resident memory per process, MiB (no perception column; target: stack < 1 GB):")
    for label, text in memory.items():
        print(f"  {label}: {text}")


def row_key(boats: int, mix: dict[str, float]) -> str:
    return "mix" if mix is MIX else str(boats)


def peak_memory(result: dict[str, Any]) -> str:
    """Each process's peak RSS and the stack's sum (log/run.json's peak_rss_mb); then the
    stack's proportional share and anonymous memory as the loops ended, which do not count a
    shared library once per process nor depend on how the page cache holds it (usage.py)."""
    rss = result.get(PEAK) or {}
    text = ", ".join(f"{name} {mb:.0f}" for name, mb in rss.items()) or "n/a"
    pss, anon = (result.get(k, {}).get("total") for k in (PSS, ANON))
    return text + (f" (PSS {pss:.0f}, anonymous {anon:.0f})" if pss and anon else "")


def keep_rtf(rtf: dict[str, list[float]], key: str, result: dict[str, Any]) -> None:
    """A cell's real-time factor, added to its row's rounds (NaN for a failed run, so the
    rounds stay aligned and a failure shows)."""
    wall = result.get("wall_s")
    rtf.setdefault(key, []).append(result["sim_s"] / wall if wall else math.nan)


def more_rounds(rtf: dict[str, list[float]], seconds: float, tmp: Path) -> None:
    """One more round of the cells the target ratios need, those the table ran, in turn."""
    for boats, mix in ((0, CIRCLES), (100, CIRCLES), (100, MIX)):
        if row_key(boats, mix) in rtf:
            keep_rtf(rtf, row_key(boats, mix), run_once(scenario(boats, 0, seconds, mix), tmp))


def print_ratios(rtf: dict[str, list[float]]) -> None:
    """The targets are ratios to the 0-boat cell of the same round (issue #17), over rounds."""
    base = rtf.get("0")
    if not base:
        return
    print(f"reference: 0 boats, no perception, RTF per round {_listed(base)}")
    targets = (("100", "100 boats", 0.6, " (paper 32/55 = 0.58)"),
               ("mix", "100 boats half on waypoints", 0.4, ""))  # fmt: skip
    for key, what, target, note in targets:
        if key in rtf:
            ratios = [a / b for a, b in zip(rtf[key], base, strict=False)]
            finite = [r for r in ratios if math.isfinite(r)]  # a failed cell: nan, shown
            if not finite:
                print(f"{what} / 0 boats: no round completed")
                continue
            median = statistics.median(finite)
            verdict = "met" if median >= target else "NOT met"
            print(f"{what} / 0 boats, per round: {_listed(ratios)}; median {median:.2f} "
                  f"(target >= {target}: {verdict}){note}")  # fmt: skip


def _listed(values: list[float]) -> str:
    return ", ".join(f"{v:.2f}" for v in values)


if __name__ == "__main__":
    main(sys.argv[1:])
