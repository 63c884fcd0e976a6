"""An outside client attacks a live run: nothing it sends may stop, stall or change the run.

Each attack runs against a real `catabot run` (every service a process, real Zenoh) from a
client session connected to the run's endpoint, while the run ticks; the run must complete
and record exactly the bytes of a clean run, and the services must have counted what they
refused. A short fuzz runs in CI; `CATABOT_SLOW=1` sends 10,000 payloads.
"""

from __future__ import annotations

import json
import math
import os
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
import zenoh
from conftest import files_of, only_run_dir, scenario_file, start, wait_for_line

from catabot.bus import codec
from catabot.bus.keys import Keys
from catabot.bus.messages import (
    Ack,
    BodyStates,
    End,
    GpsFix,
    ImuSample,
    ThrustCmd,
    Tick,
    TwistCmd,
    WaypointsCmd,
)
from catabot.bus.session import Connection, free_port, open_session

pytestmark = pytest.mark.timeout(240)
WORLD = "hostile"
KEYS = Keys(WORLD)
DT = 10_000_000
Attack = Callable[[zenoh.Session, int], None]  # (client session, round) -> puts


def _scenario(tmp: Path) -> Path:
    data = {
        "name": WORLD, "seed": 5, "duration_s": 4.0,
        "clock": {"realtime_factor": 2.0},
        "vessels": [{
            "id": "ego", "script": [{"t_s": 0.5, "thrust": [0.6, 0.8]}],
            "sensors": [{"name": "imu", "type": "imu", "rate_hz": 50.0},
                        {"name": "gps", "type": "gps", "rate_hz": 10.0}],
        }],
        "buoys": [{"id": "mark", "x_m": 30.0, "y_m": 10.0}],
        "traffic": {"count": 2},
    }  # fmt: skip
    return scenario_file(tmp, data)


def _run(
    tmp: Path, tag: str, attack: Attack | None, *, router: str = ""
) -> tuple[dict[str, bytes], dict[str, object]]:
    """One run, attacked while it ticks (through `router`: from before it starts); its
    recorded files and its log/run.json."""
    out, endpoint = tmp / tag, router or f"tcp/127.0.0.1:{free_port()}"
    out.mkdir()
    where = ("--connect", endpoint) if router else ("--listen", endpoint)
    proc = start("run", str(_scenario(tmp)), "--out", str(out), "--quiet", *where)
    if attack is not None:
        mode = "client" if router else "peer"
        with open_session(Connection(connect=(endpoint,), mode=mode)) as client:
            if not router:
                _until_ticking(client)
            for n in range(10):  # ~1 s of attacks, then let the run finish
                attack(client, n)
                time.sleep(0.1)
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == 0, err
    run = only_run_dir(out)
    files = files_of(run, ("*.csv", "*.mcap", "metrics.json", "dataset/**/*"))
    return files, json.loads((run / "log" / "run.json").read_text())


def _until_ticking(client: zenoh.Session) -> None:
    sub = client.declare_subscriber(KEYS.vessel_state("ego"), zenoh.handlers.RingChannel(1))
    limit = time.monotonic() + 30
    while sub.try_recv() is None:
        assert time.monotonic() < limit, "the run never started"
        time.sleep(0.05)
    sub.undeclare()


@pytest.fixture(scope="module")
def clean(tmp_path_factory: pytest.TempPathFactory) -> dict[str, bytes]:
    files, record = _run(tmp_path_factory.mktemp("clean"), "clean", None)
    assert record["rejected"] == {}
    return files


def _states(tick: int, ids: tuple[str, ...], stamp: int | None = None) -> bytes:
    n = len(ids)
    z3, q = np.zeros((n, 3)), np.tile([0.0, 0.0, 0.0, 1.0], (n, 1))
    stamp_ns = (tick + 1) * DT if stamp is None else stamp
    return codec.encode(BodyStates(tick, stamp_ns, ids, z3 + 50.0, q, z3, z3, z3, z3))


def wildcard_puts(client: zenoh.Session, n: int) -> None:
    """One byte on every key of the world, and a valid thrust on every vessel's thrust key."""
    client.put(KEYS.all(), b"\x01")
    client.put(f"{KEYS.prefix}/vessel/*/cmd/thrust", codec.encode(ThrustCmd((1.0, -1.0))))


def clock_forgeries(client: zenoh.Session, n: int) -> None:
    """Ticks, ends and acks in the clock's own format, from a stranger's session."""
    run = "0" * 12
    client.put(KEYS.end(), codec.encode(End(run, 5, "completed")))
    client.put(KEYS.tick(), codec.encode(Tick(run, 0, 0, DT, (), ack_every=0)))
    client.put(KEYS.tick(), codec.encode(Tick(run, 3000, 3000 * DT, DT, (), 20)))
    client.put(KEYS.tick(), codec.encode(Tick(run, 10, 10 * DT, DT, ("physics",), 20)))
    for name in ("physics", "sensors", "traffic", "recorder"):
        client.put(KEYS.ack(name), codec.encode(Ack(run, 399)))


def lockstep_forgeries(client: zenoh.Session, n: int) -> None:
    """Lockstep samples from a non-participant: other bodies, far tags, tick -1, wild stamps."""
    client.put(KEYS.world_states(), _states(n, ("intruder",)))
    ids = ("ego", "boat_000", "boat_001", "mark")
    client.put(KEYS.world_states(), _states(2**31, ids))
    client.put(KEYS.world_states(), _states(n + 1, ids, stamp=2**62))
    client.put(KEYS.guidance_states(), _states(10 * n + 9, ids))  # the traffic's copy
    imu = ImuSample(-1, 0, (0.0, 0.0, 0.0, 1.0), (9.0, 9.0, 9.0), (0.0, 0.0, 9.8))
    client.put(KEYS.sensor("ego", "imu"), codec.encode(imu))
    client.put(KEYS.sensor("ego", "gps"), codec.encode(GpsFix(-1, -5, 1.0, 2.0, 3.0, 0.0, 0.0)))


def bad_commands(client: zenoh.Session, n: int) -> None:
    """Commands any client may send, but that no vessel can use."""
    client.put(KEYS.cmd_thrust("ego"), codec.encode(ThrustCmd((math.nan, 0.5))))
    client.put(KEYS.cmd_thrust("ego"), codec.encode(ThrustCmd((0.5,), tick=-1, stamp_ns=-7)))
    client.put(KEYS.cmd_twist("ego"), codec.encode(TwistCmd(math.inf, 0.0)))
    client.put(KEYS.cmd_twist("boat_000"), codec.encode(TwistCmd(1.0, 0.1, tick=5)))
    client.put(
        KEYS.cmd_waypoints("boat_001"), codec.encode(WaypointsCmd((1.0, 2.0, 3.0), 2.0, 1.0))
    )
    client.put(KEYS.cmd_waypoints("boat_001"), codec.encode(WaypointsCmd((), 1.0, 1.0, "jump")))


def impostor_tokens(client: zenoh.Session, n: int) -> None:
    """Liveliness tokens claiming the names of the run's participants."""
    if n == 0:
        for name in ("physics", "conductor", "recorder"):
            client.liveliness().declare_token(KEYS.live(name, "1" * 32))


ATTACKS = [wildcard_puts, clock_forgeries, lockstep_forgeries, bad_commands, impostor_tokens]
REFUSED = {  # who must have counted what, per attack
    "wildcard_puts": [("physics", "no such stream")],  # once, by its watch on every command
    "clock_forgeries": [("conductor", "ack from a stranger")],
    "lockstep_forgeries": [("recorder", "not from its producer"),
                           ("traffic", "not from its producer")],  # its copy of the states
    "bad_commands": [("physics", "invalid content")],
    "impostor_tokens": [("conductor", "token contradicts the roster")],
}  # fmt: skip


@pytest.mark.parametrize("attack", ATTACKS, ids=[a.__name__ for a in ATTACKS])
def test_the_run_completes_with_a_clean_runs_bytes(
    tmp_path: Path, clean: dict[str, bytes], attack: Attack
) -> None:
    files, record = _run(tmp_path, attack.__name__, attack)
    assert record["reason"] == "completed" and record["error"] == ""
    assert files.keys() == clean.keys()
    assert [n for n in files if files[n] != clean[n]] == []
    for who, reason in REFUSED[attack.__name__]:
        assert record["rejected"][who][reason] > 0, record["rejected"]  # type: ignore[index]


def test_a_forged_clock_before_tick_0_is_not_adopted(
    tmp_path: Path, clean: dict[str, bytes]
) -> None:
    """Through a router, every process a client: forged ticks and ends from the moment the
    services start, before the conductor's first grant."""
    endpoint = f"tcp/127.0.0.1:{free_port()}"
    router = start("router", "--listen", endpoint)
    try:
        wait_for_line(router, "zenoh router listening")
        files, record = _run(tmp_path, "early", clock_forgeries, router=endpoint)
    finally:
        router.terminate()
        router.wait(timeout=10)
    assert record["reason"] == "completed"
    assert [n for n in files if files[n] != clean[n]] == []


def test_a_fuzz_of_payloads_on_every_subscribed_key_changes_nothing(
    tmp_path: Path, clean: dict[str, bytes]
) -> None:
    total = 10_000 if os.environ.get("CATABOT_SLOW") else 1_500
    rng = np.random.default_rng(11)
    keys = [KEYS.tick(), KEYS.end(), KEYS.ack("physics"), KEYS.world_states(),
            KEYS.guidance_states(), KEYS.world_twists(), KEYS.sensor("ego", "imu"),
            KEYS.cmd_thrust("ego"),
            KEYS.cmd_twist("boat_000"), KEYS.cmd_waypoints("boat_001")]  # fmt: skip
    payloads = [_fuzzed(rng) for _ in range(total)]

    def fuzz(client: zenoh.Session, n: int) -> None:
        for i in range(n * total // 10, (n + 1) * total // 10):
            client.put(keys[i % len(keys)], payloads[i])

    files, record = _run(tmp_path, "fuzz", fuzz)
    assert record["reason"] == "completed"
    assert [n for n in files if files[n] != clean[n]] == []


def _fuzzed(rng: np.random.Generator) -> bytes:
    """Random bytes, or a valid message cut short or with a byte flipped (never a usable
    command: a flipped valid one is cut too, so it cannot decode)."""
    valid = codec.encode(TwistCmd(float(rng.normal()), float(rng.normal())))
    kind = rng.integers(3)
    if kind == 0:
        return rng.bytes(int(rng.integers(0, 64)))
    cut = valid[: int(rng.integers(0, len(valid) - 1))]
    if kind == 1 or not cut:
        return cut
    i = int(rng.integers(len(cut)))
    return cut[:i] + bytes([cut[i] ^ 0xFF]) + cut[i + 1 :]
