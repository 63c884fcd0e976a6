"""The ROS 2 gateway's cost (issue "ROS 2 without a line of CataBot").

1. Gateway cost per tick, in process: the ego with a 32 x 512 LiDAR at 10 Hz (16384 points a
   scan) and a 640 x 480 camera at 10 Hz (all five images and CameraInfo), 100 traffic boats
   (101 Odometry a tick), /tf and /clock every tick; CPU of the gateway's process (its
   Zenoh threads included) per tick, with nobody listening and with a listener process
   subscribed to every topic in each convention. Median of REPEATS, interleaved.
2. The full stack (`catabot run`, Table II's rows): real-time factor without the gateway,
   with it observing and nobody listening, and with a listener on every topic (bridge
   convention). Target: with the gateway on, >= 90% of the real-time factor without it.

Usage: python -m benchmarks ros  (or python -m benchmarks.ros [seconds])
"""

from __future__ import annotations

import json
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np

from benchmarks.table2 import scenario as table2_scenario
from catabot.bus.messages import BodyStates, CameraFrame, LidarScan, Message
from catabot.bus.session import Connection, free_port, open_session
from catabot.config.load import parse_scenario
from catabot.world.world import World
from services.ros.gateway import Gateway

REPEATS = 5
TICKS = 200
DT = 10_000_000
MODES = (  # label, ros.mode, the listener's convention (None: no listener)
    ("nobody listening", "both", None),
    ("bridge", "bridge", "bridge"),
    ("rmw_zenoh", "rmw_zenoh", "rmw_zenoh"),
    ("both, rmw listener", "both", "rmw_zenoh"),
)


def workload(mode: str) -> dict[str, Any]:
    return {
        "name": "rosbench",
        "seed": 1,
        "vessels": [{"id": "ego", "pose": {"x_m": 0.0, "y_m": 0.0}, "sensors": [
            {"name": "lidar", "type": "lidar", "rate_hz": 10.0},
            {"name": "camera", "type": "camera", "rate_hz": 10.0},
        ]}],
        "traffic": {"count": 100},
        "ros": {"mode": mode},
    }  # fmt: skip


def _scan(rng: np.random.Generator) -> LidarScan:
    p = 32 * 512
    return LidarScan(
        0, 0, rng.normal(size=(p, 3)).astype(np.float32), rng.random(p, np.float32),
        np.repeat(np.arange(32, dtype=np.uint16), 512), rng.integers(0, 5, p, np.uint8),
        rng.integers(0, 99, p, np.int32), rng.random(p) < 0.01, np.ones((32, 512), np.float32),
    )  # fmt: skip


def _frame(rng: np.random.Generator) -> CameraFrame:
    h, w = 480, 640
    return CameraFrame(
        0, 0, w, h, 1.4, 0, rng.integers(0, 256, (h, w, 3), np.uint8),
        rng.random((h, w), np.float32), rng.integers(-127, 128, (h, w, 3), np.int8),
        rng.integers(0, 5, (h, w), np.uint8), rng.integers(0, 99, (h, w), np.uint16),
        np.zeros((0, 6), np.float32), np.zeros((0, 2), np.uint8),
    )  # fmt: skip


def feeds(world: World) -> list[dict[str, list[Message]]]:
    """Ten ticks of inputs: states every tick, a scan and a frame at the first."""
    rng = np.random.default_rng(1)
    n = len(world.bodies)
    lidar, camera = (s.key for s in world.sensors)
    out = []
    for k in range(10):
        arrays = (rng.normal(size=(n, c)) for c in (3, 4, 3, 3, 3, 3))
        states = BodyStates(k, (k + 1) * DT, world.body_ids, *arrays)
        inputs: dict[str, list[Message]] = {world.streams.states.key: [states]}
        if k == 0:
            inputs[lidar], inputs[camera] = [_scan(rng)], [_frame(rng)]
        out.append(inputs)
    return out


def gateway_cost(mode: str, listener: str | None, folder: Path) -> float:
    """ms of CPU per tick of the gateway's process, `listener` subscribed in a process."""
    data = workload(mode)
    world = World.resolve(parse_scenario(data))
    endpoint = f"tcp/127.0.0.1:{free_port()}"
    path = folder / "rosbench.json"
    path.write_text(json.dumps(data))
    with open_session(Connection(listen=(endpoint,), timestamping=True)) as session:
        gateway = Gateway(world, world.scenario.ros, session)  # type: ignore[arg-type]
        proc = _listen(endpoint, path, listener) if listener else None
        try:
            _until_watched(gateway, listener is not None)
            inputs = feeds(world)
            for k in range(20):
                gateway.publish(inputs[k % 10], clock_from_states=True)
            start = time.process_time()
            for k in range(TICKS):
                gateway.publish(inputs[k % 10], clock_from_states=True)
                gateway.commands()
            cpu = (time.process_time() - start) / TICKS
        finally:
            gateway.close()
            if proc is not None:
                proc.terminate()
                proc.communicate(timeout=10)
    return cpu * 1e3


def _listen(endpoint: str, scenario: Path, mode: str) -> subprocess.Popen[str]:
    cmd = [sys.executable, "-m", "benchmarks.ros_listener", "--connect", endpoint,
           "--scenario", str(scenario), "--mode", mode]  # fmt: skip
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    assert proc.stdout is not None
    proc.stdout.readline()  # "listening to N topics"
    return proc


def _until_watched(gateway: Gateway, expected: bool, limit_s: float = 20.0) -> None:
    end = time.monotonic() + limit_s
    while expected and not all(o.watched for o in gateway.odom) and time.monotonic() < end:
        time.sleep(0.05)


def full_stack(
    data: dict[str, Any], folder: Path, listener: bool
) -> tuple[float, dict[str, float]]:
    """The real-time factor of one `catabot run` (and a listener process if asked), and the
    CPU per tick of each service (ms; the listener, the ROS side, not counted)."""
    endpoint = f"tcp/127.0.0.1:{free_port()}"
    path = folder / f"{data['name']}.json"
    path.write_text(json.dumps(data))
    proc = _listen(endpoint, path, "bridge") if listener else None
    out = folder / f"out-{time.monotonic_ns()}"
    cmd = [sys.executable, "-m", "catabot", "run", str(path), "--quiet", "--out", str(out),
           "--listen", endpoint]  # fmt: skip
    run = subprocess.run(cmd, capture_output=True, text=True)
    if proc is not None:
        proc.terminate()
        proc.communicate(timeout=10)
    result = json.loads(next(out.glob("*/log/run.json")).read_text()) if run.returncode == 0 else {}
    if not result:
        return float("nan"), {}
    ticks = max(int(result["ticks"]), 1)
    cpu_ms = {name: 1e3 * s / ticks for name, s in result["cpu_s"].items()}
    return float(result["sim_s"] / result["wall_s"]), cpu_ms


def variants(boats: int, column: int, seconds: float) -> dict[str, tuple[dict[str, Any], bool]]:
    base = table2_scenario(boats, column, seconds)
    on = {**base, "ros": {"mode": "both"}}
    bridge = {**base, "ros": {"mode": "bridge"}}
    return {"without gateway": (base, False), "gateway, nobody listening": (on, False),
            "gateway + listener on every topic": (bridge, True)}  # fmt: skip


def main(argv: list[str] | None = None) -> None:
    args = sys.argv[1:] if argv is None else argv
    numbers = [a for a in args if a.replace(".", "", 1).isdigit()]
    seconds = float(numbers[0]) if numbers else 8.0
    with tempfile.TemporaryDirectory(prefix="rosbench-") as tmp:
        folder = Path(tmp)
        print("Gateway CPU per tick (ms, process incl. Zenoh threads; 101 Odometry + /tf + "
              "/clock a tick, 32x512 LiDAR and 640x480 camera at 10 Hz):")  # fmt: skip
        costs: dict[str, list[float]] = {label: [] for label, _, _ in MODES}
        for _ in range(REPEATS):
            for label, mode, listener in MODES:
                costs[label].append(gateway_cost(mode, listener, folder))
        for label, values in costs.items():
            print(f"  {label:22s} {statistics.median(values):6.2f} ms  (runs: "
                  f"{', '.join(f'{v:.2f}' for v in values)})")  # fmt: skip
        print(
            f"Full stack ({seconds:g} s simulated, median of {REPEATS}, interleaved): real-time "
            "factor, and CPU per tick of every CataBot process together (on two busy cores the "
            "RTF is CPU-bound, so the CPU ratio without/with is the RTF ratio a quiet machine "
            "shows). Target: with the gateway >= 0.90 of without."
        )
        for boats, column, label in ROWS:
            _full_stack_row(variants(boats, column, seconds), folder, label)


ROWS = ((100, 0, "100 boats, no perception"), (0, 2, "0 boats, four camera outputs"))


def _full_stack_row(
    cases: dict[str, tuple[dict[str, Any], bool]], folder: Path, label: str
) -> None:
    got: dict[str, list[tuple[float, dict[str, float]]]] = {name: [] for name in cases}
    for _ in range(REPEATS):
        for name, (data, listener) in cases.items():
            got[name].append(full_stack(data, folder, listener))
    base_rtf = statistics.median(r for r, _ in got["without gateway"])
    base_cpu = statistics.median(sum(c.values()) for _, c in got["without gateway"])
    for name, values in got.items():
        rtf = statistics.median(r for r, _ in values)
        cpu = statistics.median(sum(c.values()) for _, c in values)
        services = {k: statistics.median(c.get(k, 0.0) for _, c in values) for k in values[0][1]}
        each = ", ".join(f"{k} {v:.2f}" for k, v in services.items())
        print(
            f"  {label:28s} {name:34s} RTF {rtf:5.2f} ({rtf / base_rtf:4.2f})  CPU "
            f"{cpu:5.2f} ms/tick ({base_cpu / cpu:4.2f}: {each})",
            flush=True,
        )


if __name__ == "__main__":
    main()
