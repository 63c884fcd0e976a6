"""Reading a long recording back by its index (issue #17: recordings that open at any length).

A synthetic harbour run with a camera goes through the recorder's own MCAP sink
(services/recorder/mcap_sink.py), once per `recording.mcap_compression`: per 10 ms tick a
`/tf`, five boats' odometry and an IMU sample (their real sizes), and at 5 Hz a 1280 x 720
rgb8 image (random pixels, which no compression shrinks: the worst case for the file's size)
and a GPS fix, 14 MB per simulated second as the issue measured; 90 s make a file over
1 GiB. Then, each in a fresh interpreter (its peak RSS is the process's, Python included):
- the last simulated minute of one boat's odometry, and of the camera's images, with `mcap`'s
  indexed reader (`make_reader(...).iter_messages(topics, starting_at)`: the summary's chunk
  indexes lead it to the chunks it needs);
- beside them the reference: the same odometry from a scan of the whole file without the
  index (`mcap`'s NonSeekingReader, what an unindexed file leaves a reader), and the raw read
  of the file (16 MiB blocks). The files are in the page cache: reads are CPU, not disk.
Target: < 1 s and < 200 MB RSS for one topic's last minute.

Usage: python -m benchmarks.recording [seconds]  (simulated seconds, default 90), or
`python -m benchmarks recording`.
"""

from __future__ import annotations

import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from mcap.reader import NonSeekingReader, make_reader

from catabot.run.usage import peak_rss_mb
from services.recorder.mcap_sink import McapSink

DT_NS = 10_000_000
CAMERA_EVERY = 20  # ticks: 5 Hz
IMAGE = 1280 * 720 * 3
SMALL = {"/tf": 620, "/ego/imu": 324, **{f"/boat_{i}/odom": 716 for i in range(5)}}
ODOM, IMAGES = "/boat_0/odom", "/ego/camera/image_raw"
SCHEMA = {"title": "bench", "type": "object"}


def write(path: Path, seconds: float, compression: str) -> float:
    """The synthetic run into `path`; CPU seconds the writing took."""
    rng = np.random.default_rng(1)
    image = rng.integers(0, 256, IMAGE, dtype=np.uint8).tobytes()
    small = {topic: rng.integers(0, 256, n, dtype=np.uint8).tobytes() for topic, n in SMALL.items()}
    start = time.process_time()
    with McapSink(path, profile="", compression=compression) as sink:
        for tick in range(round(seconds * 1e9 / DT_NS)):
            stamp = tick * DT_NS
            for topic, data in small.items():
                sink.write_json(topic, "bench", SCHEMA, data, stamp_ns=stamp)
            if tick % CAMERA_EVERY == 0:
                sink.write_json(IMAGES, "bench", SCHEMA, image, stamp_ns=stamp)
                sink.write_json("/ego/gps/fix", "bench", SCHEMA, small["/ego/imu"], stamp_ns=stamp)
            if tick % 10 == 9:
                sink.flush()  # as the recorder does, every 0.1 s of wall time at most
    return time.process_time() - start


def read(path: Path, how: str, topic: str) -> dict[str, float]:
    """One way of reading `topic`'s last minute (run in a fresh interpreter)."""
    start = time.perf_counter()
    count = size = 0
    with open(path, "rb") as f:
        if how == "indexed":
            reader = make_reader(f)
            summary = reader.get_summary()
            assert summary is not None and summary.statistics is not None
            last = summary.statistics.message_end_time - 60 * 10**9
            for _, _, message in reader.iter_messages(topics=[topic], starting_at=last):
                count, size = count + 1, size + len(message.data)
        elif how == "scan":
            found = []
            for _, _, message in NonSeekingReader(f).iter_messages(topics=[topic]):
                found.append(message.log_time)  # the end is known only at the end
            count = sum(1 for t in found if t >= found[-1] - 60 * 10**9)
        else:
            while block := f.read(16 << 20):
                size += len(block)
    seconds = time.perf_counter() - start
    return {"seconds": seconds, "rss_mb": peak_rss_mb(), "messages": count, "mb": size / 1e6}


def measured(path: Path, how: str, topic: str) -> dict[str, float]:
    code = (
        "import json, sys; from pathlib import Path; from benchmarks.recording import read; "
        "print(json.dumps(read(Path(sys.argv[1]), sys.argv[2], sys.argv[3])))"
    )
    out = subprocess.run(
        [sys.executable, "-c", code, str(path), how, topic], capture_output=True, text=True
    )
    if out.returncode != 0:
        raise RuntimeError(out.stderr.strip().splitlines()[-1])
    result: dict[str, float] = json.loads(out.stdout)
    return result


def row(label: str, r: dict[str, float]) -> str:
    what = f"{int(r['messages'])} messages" if r["messages"] else f"{r['mb']:.0f} MB"
    return f"  {label:<44} {r['seconds']:7.2f} s {r['rss_mb']:7.0f} MB RSS   ({what})"


def main(argv: list[str] | None = None) -> None:
    args = sys.argv[1:] if argv is None else argv
    numbers = [a for a in args if a.replace(".", "", 1).isdigit()]
    seconds = float(numbers[0]) if numbers else 90.0
    idle = measured(Path(__file__), "raw", "")  # an interpreter that reads a small file
    print(
        f"Recording: {seconds:g} s simulated, camera 1280 x 720 rgb8 at 5 Hz + 5 boats, IMU, "
        f"/tf at 100 Hz; peak RSS of a bare reading interpreter {idle['rss_mb']:.0f} MB"
    )
    with tempfile.TemporaryDirectory(prefix="recording-") as tmp:
        for compression in ("zstd", "lz4", "none"):
            path = Path(tmp) / f"{compression}.mcap"
            cpu = write(path, seconds, compression)
            with open(path, "rb") as f:
                summary = make_reader(f).get_summary()
            chunks = len(summary.chunk_indexes) if summary else 0
            size = path.stat().st_size / 2**30
            print(
                f"{compression}: {size:.2f} GiB, {chunks} chunks, written in {cpu:.1f} s CPU "
                f"({1e3 * cpu / seconds:.0f} ms per simulated s)"
            )
            print(row(f"{ODOM} last minute, indexed", measured(path, "indexed", ODOM)))
            print(row(f"{IMAGES} last minute, indexed", measured(path, "indexed", IMAGES)))
            print(row(f"{ODOM} last minute, whole-file scan", measured(path, "scan", ODOM)))
            print(row("raw read of the file", measured(path, "raw", "")), flush=True)
            path.unlink()


if __name__ == "__main__":
    main(sys.argv[1:])
