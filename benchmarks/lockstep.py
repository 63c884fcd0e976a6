"""Empty-tick rate of the lockstep against a raw Zenoh tick-and-ack loop.

Both use real processes and the same embedded peer mesh on loopback; the raw loop is
the floor cost of one broadcast plus N acks, so the ratio is what the protocol
(codec, Jacobi inbox, deadline bookkeeping) costs on top of Zenoh itself. The ratio is
for a window of one tick (a barrier per tick, like the raw loop); the last column is the
scenario's default window (`clock.window_ticks`: a grant and acks every half window).
"""

from __future__ import annotations

import queue
import subprocess
import sys
import time

import zenoh

from catabot.bus.conductor import ClockSpec, Conductor
from catabot.bus.keys import Keys
from catabot.bus.session import Connection, free_port, open_session
from catabot.config.scenario import ClockConfig

TICKS = 3000
PEERS = (1, 2, 4, 8)
TARGET = 0.5  # 4 participants at a strict barrier, of the raw Zenoh tick-and-ack loop


def _spawn(mode: str, endpoint: str, world: str, names: list[str]) -> list[subprocess.Popen[bytes]]:
    cmd = [sys.executable, "-m", "benchmarks.peer", mode, "--connect", endpoint, "--world", world]
    return [subprocess.Popen([*cmd, "--name", n, "--peers", ",".join(names)]) for n in names]


def catabot_rate(n: int, window: int = 1) -> float:
    port = free_port()
    session = open_session(Connection(listen=(f"tcp/127.0.0.1:{port}",)))
    names = [f"p{i}" for i in range(n)]
    world = f"bench{n}"
    procs = _spawn("catabot", f"tcp/127.0.0.1:{port}", world, names)
    spec = ClockSpec(
        dt_ns=1_000_000, ticks=TICKS, participants=tuple(names), deadline_s=10, window_ticks=window
    )
    conductor = Conductor(session, Keys(world), spec)
    result = conductor.run()
    conductor.close()
    for p in procs:
        p.wait(timeout=30)
    session.close()
    if result.error:
        raise RuntimeError(result.error)
    return TICKS / result.wall_s


def raw_rate(n: int) -> float:
    port = free_port()
    session = open_session(Connection(listen=(f"tcp/127.0.0.1:{port}",)))
    world = f"raw{n}"
    names = [f"r{i}" for i in range(n)]
    acks = session.declare_subscriber(f"raw/{world}/ack/*", zenoh.handlers.FifoChannel(4096))
    present: queue.SimpleQueue[str] = queue.SimpleQueue()
    live = session.liveliness().declare_subscriber(
        f"raw/{world}/live/*", lambda s: present.put(str(s.key_expr)), history=True
    )
    procs = _spawn("raw", f"tcp/127.0.0.1:{port}", world, names)
    for _ in names:
        present.get(timeout=30)
    pub = session.declare_publisher(
        f"raw/{world}/tick", congestion_control=zenoh.CongestionControl.BLOCK
    )
    _handshake(pub, acks, n)
    start = time.perf_counter()
    for k in range(TICKS):
        pub.put(k.to_bytes(4, "little"))
        for _ in names:
            acks.recv()
    rate = TICKS / (time.perf_counter() - start)
    pub.put(b"end")
    for p in procs:
        p.wait(timeout=30)
    live.undeclare()
    session.close()
    return rate


def _handshake(pub: zenoh.Publisher, acks: zenoh.Subscriber, n: int) -> None:
    """Repeat a warm-up tick until every peer has answered once, then drain: a tick sent
    before a peer's subscription is routed would otherwise be lost and the loop would hang."""
    seen: set[str] = set()
    limit = time.monotonic() + 30
    while len(seen) < n and time.monotonic() < limit:
        pub.put(b"w")
        time.sleep(0.05)
        while (sample := acks.try_recv()) is not None:
            seen.add(str(sample.key_expr))
    time.sleep(0.1)
    while acks.try_recv() is not None:
        pass
    if len(seen) < n:
        raise RuntimeError(f"only {len(seen)} of {n} raw peers answered the warm-up")


def main() -> None:
    print("\nLockstep empty-tick rate (real processes, loopback peer mesh)")
    window = ClockConfig().window_ticks
    head = (
        "participants",
        "catabot ticks/s",
        "raw zenoh ticks/s",
        "ratio",
        f"window {window} ticks/s",
    )
    print(" | ".join(head))
    print("-|-".join("-" * len(h) for h in head))
    ratios = {}
    for n in PEERS:
        ours, raw, windowed = catabot_rate(n), raw_rate(n), catabot_rate(n, window)
        ratios[n] = ours / raw
        cells = (f"{n}", f"{ours:.0f}", f"{raw:.0f}", f"{ours / raw:.2f}", f"{windowed:.0f}")
        print(" | ".join(c.rjust(len(h)) for c, h in zip(cells, head, strict=True)))
    if 4 in ratios:  # one sample a cell, one after the other: a loaded machine moves it
        met = "met" if ratios[4] >= TARGET else "NOT met"
        print(f"target: 4 participants, barrier >= {TARGET} of raw Zenoh: {ratios[4]:.2f}, {met}")


if __name__ == "__main__":
    main()
