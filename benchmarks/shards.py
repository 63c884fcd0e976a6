"""The sensor farm: the full stack with the sensors split over 1, 2 and 4 processes.

Two set-ups, each a real `catabot run --quiet` per cell (recorder on):
- Table II's 100-boat row with the four-output camera (the ego: a 32 x 512 LiDAR, radar,
  IMU, GPS and a 640 x 480 camera, all at 10 Hz but the IMU), the row where sensors cost most;
- ten egos, each with a 32 x 512 LiDAR and a 640 x 480 four-output camera at 10 Hz: the case
  one process cannot carry.
Then a cost model from the one-shard cells: CPU per LiDAR scan, per camera frame, per body
per tick (physics, traffic and recorder: the 100-boat cell against a 0-boat one), and the
clock's fixed cost per tick. From those it projects how many LiDAR+camera vessels M machines
of C cores keep in real time, and predicts the 2- and 4-shard cells' RTF on this machine to
check itself against the measurements.

Usage: python -m benchmarks.shards [seconds]  (simulated seconds per cell, default 20)
"""

from __future__ import annotations

import os
import sys
import tempfile
from pathlib import Path
from typing import Any

from benchmarks.table2 import run_once
from benchmarks.table2 import scenario as table2_scenario

SHARDS = (1, 2, 4)
EGOS = 10
UTILISATION = 0.9  # of each core, what a CPU-bound stack reached in Table II (91 %)
LIDAR = {"name": "lidar", "type": "lidar", "rate_hz": 10.0}
CAMERA = {"name": "camera", "type": "camera", "rate_hz": 10.0}


def table2(boats: int, shards: int, seconds: float) -> dict[str, Any]:
    data = table2_scenario(boats, 2, seconds)  # the four-output camera column
    return data | {"name": f"farm_t2_{boats}_{shards}", "sensors": {"shards": shards}}


def egos(shards: int, seconds: float) -> dict[str, Any]:
    vessels = [
        {"id": f"ego{i}", "sensors": [LIDAR, CAMERA],
         "pose": {"x_m": 40.0 * (i % 5), "y_m": 40.0 * (i // 5), "yaw_rad": 0.3 * i}}
        for i in range(EGOS)
    ]  # fmt: skip
    return {"name": f"farm_egos_{shards}", "seed": 1, "duration_s": seconds,
            "sensors": {"shards": shards}, "vessels": vessels}  # fmt: skip


def rtf(result: dict[str, Any]) -> float:
    return float(result["sim_s"]) / float(result["wall_s"]) if result.get("wall_s") else 0.0


def cpu_ms(result: dict[str, Any], prefix: str) -> float:
    """CPU ms per tick of the services whose name starts with `prefix` (every shard)."""
    ticks = max(int(result.get("ticks", 0)), 1)
    cpu = result.get("cpu_s") or {}
    return 1e3 * sum(s for name, s in cpu.items() if name.startswith(prefix)) / ticks


def row(label: str, shards: int, result: dict[str, Any]) -> str:
    if result.get("error") or not result.get("wall_s"):
        return f"| {label} | {shards} | failed: {str(result.get('error'))[:60]} | | | |"
    per = [cpu_ms(result, p) for p in ("physics", "sensors", "recorder")]
    shard_cpu = [
        1e3 * s / max(int(result["ticks"]), 1)
        for n, s in (result.get("cpu_s") or {}).items()
        if n.startswith("sensors")
    ]
    spread = "/".join(f"{c:.1f}" for c in shard_cpu)
    return (f"| {label} | {shards} | {rtf(result):.2f} | {per[0]:.2f} | {per[1]:.2f} ({spread}) "
            f"| {per[2]:.2f} |")  # fmt: skip


def measure(seconds: float, tmp: Path) -> dict[tuple[str, int], dict[str, Any]]:
    print("| set-up | shards | RTF | physics ms/tick | sensors ms/tick (each shard) "
          "| recorder ms/tick |\n|---|---:|---:|---:|---:|---:|")  # fmt: skip
    results: dict[tuple[str, int], dict[str, Any]] = {}
    for label, make in (("Table II 100 boats, 4-output camera", table2_100),
                        (f"{EGOS} egos, LiDAR + camera each", egos)):  # fmt: skip
        for shards in SHARDS:
            results[(label, shards)] = run_once(make(shards, seconds), tmp)
            print(row(label, shards, results[(label, shards)]), flush=True)
    results[("empty", 1)] = run_once(table2(0, 1, seconds), tmp)
    return results


def table2_100(shards: int, seconds: float) -> dict[str, Any]:
    return table2(100, shards, seconds)


def cost_model(results: dict[tuple[str, int], dict[str, Any]]) -> None:
    """CPU per scan, per frame, per body tick; projections; the 2- and 4-shard check."""
    t2 = results[("Table II 100 boats, 4-output camera", 1)]
    farm = {n: results[(f"{EGOS} egos, LiDAR + camera each", n)] for n in SHARDS}
    empty = results[("empty", 1)]
    if not all(r.get("wall_s") for r in (t2, empty, *farm.values())):
        print("cost model: a cell failed; nothing projected")
        return
    # Ten egos: every tenth tick each ego scans once and takes a frame.
    per_vessel_ms = cpu_ms(farm[1], "sensors") * 10 / EGOS  # one scan + one frame, CPU ms
    fixed_ms = sum(cpu_ms(empty, p) for p in ("physics", "recorder", "sensors"))
    body_ms = (sum(cpu_ms(t2, p) for p in ("physics", "traffic", "recorder"))
               - sum(cpu_ms(empty, p) for p in ("physics", "recorder"))) / 100  # fmt: skip
    cores = os.cpu_count() or 1
    print(f"\ncost model (CPU, this machine, {cores} cores): a LiDAR scan + a camera frame "
          f"{per_vessel_ms:.1f} ms; a body {1e3 * body_ms:.1f} us a tick; the 0-boat stack "
          f"(camera ego) {fixed_ms:.2f} ms a tick")  # fmt: skip
    need_s = per_vessel_ms * 10 / 1e3  # CPU seconds a simulated second per LiDAR+camera vessel
    print("| machines x cores | LiDAR + camera vessels in real time (10 Hz each) |\n|---|---:|")
    for machines, c in ((1, cores), (2, cores), (4, cores), (4, 16)):
        print(f"| {machines} x {c} | {int(UTILISATION * machines * c / need_s)} |")
    total_s = sum(cpu_ms(farm[1], p) for p in ("physics", "sensors", "recorder")) * 100 / 1e3
    ceiling = cores * UTILISATION / total_s  # CPU-bound: every core busy, work balanced
    for n in SHARDS:
        print(
            f"{n} shard(s), {EGOS} egos: measured RTF {rtf(farm[n]):.2f}, CPU-bound ceiling "
            f"{ceiling:.2f} ({total_s:.2f} CPU s a simulated second on {cores} cores)"
        )


def main(argv: list[str] | None = None) -> None:
    args = sys.argv[1:] if argv is None else argv
    numbers = [a for a in args if a.replace(".", "", 1).isdigit()]
    seconds = float(numbers[0]) if numbers else 20.0
    print(f"Sensor farm: {seconds:g} s simulated per cell, recorder on")
    with tempfile.TemporaryDirectory(prefix="shards-") as tmp:
        cost_model(measure(seconds, Path(tmp)))


if __name__ == "__main__":
    main()
