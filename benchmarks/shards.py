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

Usage: python -m benchmarks.shards [seconds [ego_seconds]]  (simulated seconds per Table II
cell, default 60, and per ten-ego cell, default 10: those run at a tenth of real time)
"""

from __future__ import annotations

import os
import sys
import tempfile
import threading
import time
from pathlib import Path
from typing import Any

from benchmarks.table2 import run_once
from benchmarks.table2 import scenario as table2_scenario
from catabot.bus.session import Connection, free_port, open_session

SHARDS = (1, 2, 4)
EGOS = 10
TICKS_PER_S = 100  # dt 10 ms
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


def measure(seconds: float, ego_seconds: float, tmp: Path) -> dict[tuple[str, int], dict[str, Any]]:
    print("| set-up | shards | RTF | physics ms/tick | sensors ms/tick (each shard) "
          "| recorder ms/tick |\n|---|---:|---:|---:|---:|---:|")  # fmt: skip
    results: dict[tuple[str, int], dict[str, Any]] = {}
    cells = (("Table II 100 boats, 4-output camera", table2_100, seconds),
             (f"{EGOS} egos, LiDAR + camera each", egos, ego_seconds))  # fmt: skip
    for label, make, cell_s in cells:
        for shards in SHARDS:
            results[(label, shards)] = run_once(make(shards, cell_s), tmp)
            print(row(label, shards, results[(label, shards)]), flush=True)
    results[("empty", 1)] = run_once(table2(0, 1, seconds), tmp)
    return results


def table2_100(shards: int, seconds: float) -> dict[str, Any]:
    return table2(100, shards, seconds)


def hop_ms(size: int, repeats: int = 40) -> float:
    """Wall ms for one message of `size` bytes from one Zenoh session to another over
    loopback TCP (two peers, as two processes of a run talk), received and copied out."""
    port = free_port()
    got = threading.Semaphore(0)
    a = open_session(Connection(listen=(f"tcp/127.0.0.1:{port}",)))
    b = open_session(Connection(connect=(f"tcp/127.0.0.1:{port}",)))
    sub = b.declare_subscriber("bench/hop", lambda s: (s.payload.to_bytes(), got.release()))
    time.sleep(0.5)  # the subscription reaches the publisher
    payload = bytes(size)
    start = time.perf_counter()
    for _ in range(repeats):
        a.put("bench/hop", payload)
        got.acquire(timeout=5)
    ms = 1e3 * (time.perf_counter() - start) / repeats
    sub.undeclare()
    b.close()
    a.close()
    return ms


def cost_model(results: dict[tuple[str, int], dict[str, Any]]) -> None:
    """CPU per scan + frame, per body tick, per hop; projections; the check against 2 and 4
    shards."""
    t2 = results[("Table II 100 boats, 4-output camera", 1)]
    farm = {n: results[(f"{EGOS} egos, LiDAR + camera each", n)] for n in SHARDS}
    empty = results[("empty", 1)]
    if not all(r.get("wall_s") for r in (t2, empty, *farm.values())):
        print("cost model: a cell failed; nothing projected")
        return
    cores = os.cpu_count() or 1
    # CPU seconds a simulated second for one LiDAR + camera vessel (a scan and a frame at
    # 10 Hz): to sense it (sensors) and to record it (the one recorder of a run).
    sense_s = cpu_ms(farm[1], "sensors") * TICKS_PER_S / 1e3 / EGOS
    record_s = cpu_ms(farm[1], "recorder") * TICKS_PER_S / 1e3 / EGOS
    body_us = 1e3 * (sum(cpu_ms(t2, p) for p in ("physics", "traffic", "recorder"))
                     - sum(cpu_ms(empty, p) for p in ("physics", "recorder"))) / 100  # fmt: skip
    frame = 640 * 480 * (3 + 4 + 12 + 2 + 4)  # colour, depth, normals, segmentation, instance
    hop = hop_ms(frame)
    print(f"\ncost model (this machine, {cores} cores, CPU s per simulated s): sensing a LiDAR + "
          f"camera vessel {sense_s:.3f}, recording it {record_s:.3f}; a body {body_us:.1f} us "
          f"a tick; one hop of a {frame / 1e6:.1f} MB camera frame {hop:.1f} ms wall")  # fmt: skip
    print("| machines x cores (sensor shards) | vessels in real time: sensing "
          "| recording (one recorder) | both |\n|---|---:|---:|---:|")  # fmt: skip
    for machines, c in ((1, cores), (2, cores), (4, cores), (4, 16)):
        hops_s = 10 * hop / 1e3 * (machines > 1)  # frames leave the machine: a hop each
        sensing = int(UTILISATION * machines * c / (sense_s + hops_s))
        recording = int(1.0 / record_s)  # one process, one core
        print(f"| {machines} x {c} | {sensing} | {recording} | {min(sensing, recording)} |")
    total_s = sum(cpu_ms(farm[1], p) for p in ("physics", "sensors", "recorder")) * 100 / 1e3
    ceiling = min(cores * UTILISATION / total_s, 1.0 / (record_s * EGOS))
    for n in SHARDS:
        print(
            f"{n} shard(s), {EGOS} egos: measured RTF {rtf(farm[n]):.3f}; predicted "
            f"{ceiling:.3f} (all cores busy, or the recorder's one core: the lower)"
        )


def main(argv: list[str] | None = None) -> None:
    args = sys.argv[1:] if argv is None else argv
    numbers = [float(a) for a in args if a.replace(".", "", 1).isdigit()]
    seconds = numbers[0] if numbers else 60.0
    ego_seconds = numbers[1] if len(numbers) > 1 else 10.0
    print(f"Sensor farm: {seconds:g} s simulated per Table II cell, {ego_seconds:g} s per "
          f"{EGOS}-ego cell, recorder on")  # fmt: skip
    with tempfile.TemporaryDirectory(prefix="shards-") as tmp:
        cost_model(measure(seconds, ego_seconds, Path(tmp)))


if __name__ == "__main__":
    main()
