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

Usage: python -m benchmarks.table2 [seconds]  (simulated seconds per run, default 5), or
`python -m benchmarks table2` (5 s).
"""

from __future__ import annotations

import json
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import Any

from catabot.config.load import parse_scenario
from catabot.config.sensors import SENSOR_TYPES
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


def main(argv: list[str] | None = None) -> None:
    args = sys.argv[1:] if argv is None else argv
    numbers = [a for a in args if a.replace(".", "", 1).isdigit()]
    seconds = float(numbers[0]) if numbers else 5.0
    missing = sorted({"lidar", "radar", "camera"} - set(SENSOR_TYPES))
    columns = [0] if "camera" not in SENSOR_TYPES else [0, 1, 2]
    print(f"Table II: {seconds:g} s simulated per run, recorder on, rain 10 mm/h")
    if missing:
        print(f"  sensor types not registered, left out: {', '.join(missing)}")
    if len(columns) < 3:
        print("  columns skipped (no camera): " + ", ".join(COLUMNS[1:]))
    has_lidar = "lidar" in SENSOR_TYPES
    usage: dict[str, str] = {}
    rtf: dict[int, float] = {}
    with tempfile.TemporaryDirectory(prefix="table2-") as tmp:
        for boats, mix in [(b, CIRCLES) for b in BOATS] + [(100, MIX)]:
            label = f"{boats:4d} boats" + (
                f" (half on waypoints, {buoys(seconds)} buoys)" if mix is MIX else ""
            )
            row = [label]
            for column in columns:
                result = run_once(scenario(boats, column, seconds, mix), Path(tmp))
                row.append(f"{COLUMNS[column]}: {cell(result, has_lidar)} "
                           f"(paper {PAPER[boats][column]} FPS)")  # fmt: skip
                if column == 0:
                    usage[label] = cpu_per_tick(result)
                    if mix is CIRCLES and result.get("wall_s"):
                        rtf[boats] = result["sim_s"] / result["wall_s"]
            print(" | ".join(row), flush=True)
    if rtf.get(0) and 100 in rtf:
        print(f"100 boats / 0 boats, no perception: {rtf[100] / rtf[0]:.2f} (paper 32/55 = 0.58)")
    print("CPU per tick in each service's stepping loop (no perception column):")
    for label, text in usage.items():
        print(f"  {label}: {text}")


if __name__ == "__main__":
    main(sys.argv[1:])
