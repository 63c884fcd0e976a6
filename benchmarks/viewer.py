"""What the live viewer costs the simulation, and how large run.rrd is.

The full stack of Table II's 100-boat row (physics at 100 Hz, 100 circling boats, the ego's
32 x 512 LiDAR at 10 Hz in 10 mm/h rain, radar, IMU, GPS, the recorder), run through
`catabot run --quiet`, without and with `--view web`: the viewer subscribes to every state,
scan and sample and logs them into its rerun server, which nobody opens (a headless sink:
no browser, no GPU). Runs alternate without/with, so load from the rest of the machine falls
on both alike; the table gives medians. Target (issue 16): the real-time factor with the
view at least 90% of the one without. Then run.rrd of the last run without the view, made
as `recording.rerun: true` makes it (`python -m services.viewer RUN --save run.rrd`): its
size per simulated minute (beside run.mcap's) and the time the conversion took.

Usage: python -m benchmarks.viewer [seconds] [pairs]  (default 10 s, 3 pairs), or
`python -m benchmarks viewer`.
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

from benchmarks.table2 import scenario

BOATS = 100
TARGET = 0.90


def run(data: dict[str, Any], folder: Path, *extra: str) -> tuple[dict[str, Any], Path, float]:
    """One `catabot run`: its log/run.json, its folder and the command's wall seconds (the
    run.json figures are the lockstep's own: start-up and the viewer's start excluded)."""
    path = folder / f"{data['name']}.json"
    path.write_text(json.dumps(data))
    out = folder / f"out-{len(list(folder.iterdir()))}"
    started = time.monotonic()
    proc = subprocess.run(
        [sys.executable, "-m", "catabot", "run", str(path), "--quiet", "--out", str(out), *extra],
        capture_output=True, text=True, stdin=subprocess.DEVNULL, check=False,
    )  # fmt: skip
    wall = time.monotonic() - started
    runs = sorted(out.glob("*/log/run.json"))
    if proc.returncode != 0 or not runs:
        raise SystemExit(f"run failed ({proc.returncode}): {proc.stderr.strip()[-400:]}")
    return json.loads(runs[-1].read_text()), runs[-1].parents[1], wall


def rtf(result: dict[str, Any]) -> float:
    return float(result["sim_s"]) / float(result["wall_s"])


def shown(run_dir: Path) -> str:
    """The viewer's own account of what it drew (log/viewer.log)."""
    lines = (run_dir / "log" / "viewer.log").read_text().splitlines()
    return next((line for line in lines if line.startswith("shown:")), "shown: ?")


def main(argv: list[str] | None = None) -> None:
    args = sys.argv[1:] if argv is None else argv
    numbers = [float(a) for a in args if a.replace(".", "", 1).isdigit()]
    seconds = numbers[0] if numbers else 10.0
    pairs = int(numbers[1]) if len(numbers) > 1 else 3
    data = scenario(BOATS, 0, seconds)
    data["name"] = "viewer_bench"
    print(f"Viewer cost: {BOATS} boats, LiDAR {10} Hz, {seconds:g} s simulated, {pairs} pairs")
    plain, viewed = [], []
    with tempfile.TemporaryDirectory(prefix="viewer-bench-") as tmp:
        folder = Path(tmp)
        for k in range(pairs):
            without, plain_dir, _ = run(data, folder)
            with_view, run_dir, _ = run(data, folder, "--view", "web")
            plain.append(rtf(without))
            viewed.append(rtf(with_view))
            print(f"  pair {k + 1}: RTF {plain[-1]:.2f} without, {viewed[-1]:.2f} with the view "
                  f"({shown(run_dir)} in {with_view['wall_s']:.1f} s)", flush=True)  # fmt: skip
        started = time.monotonic()
        subprocess.run([sys.executable, "-m", "services.viewer", str(plain_dir), "--save",
                        str(plain_dir / "run.rrd")], check=True)  # fmt: skip
        convert = time.monotonic() - started
        minutes = float(without["sim_s"]) / 60.0
        rrd = (plain_dir / "run.rrd").stat().st_size / 1e6 / minutes
        mcap = (plain_dir / "run.mcap").stat().st_size / 1e6 / minutes
    ratio = statistics.median(viewed) / statistics.median(plain)
    verdict = "met" if ratio >= TARGET else "NOT met"
    print("\n| what | median | runs | target |")
    print("|---|---:|---|---|")
    print(f"| RTF without the view | {statistics.median(plain):.2f} | "
          f"{', '.join(f'{v:.2f}' for v in plain)} | |")  # fmt: skip
    print(f"| RTF with `--view web` | {statistics.median(viewed):.2f} | "
          f"{', '.join(f'{v:.2f}' for v in viewed)} | |")  # fmt: skip
    print(f"| with / without | **{ratio:.2f}** | | >= {TARGET:.2f}: {verdict} |")
    print(f"| run.rrd per simulated minute | {rrd:.0f} MB | | (run.mcap: {mcap:.0f} MB/min) |")
    print(f"| making run.rrd after the run | {convert:.1f} s | | {seconds:g} s simulated |")


if __name__ == "__main__":
    main(sys.argv[1:])
