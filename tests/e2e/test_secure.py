"""The secure profile: TLS, a login per process, and a router whose access control lets each
name publish only its own keys. Without a login nobody connects; with one, a client that
may only observe cannot drive the clock or a vessel; a commanding client can command."""

from __future__ import annotations

import json
import shutil
import threading
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from conftest import catabot, files_of, only_run_dir, scenario_file, start, wait_for_line

from catabot.bus import codec
from catabot.bus.keys import Keys
from catabot.bus.messages import Ack, End, ThrustCmd, Tick
from catabot.bus.session import Connection, SessionError, free_port, open_session
from catabot.client import Client

pytestmark = pytest.mark.skipif(shutil.which("openssl") is None, reason="needs openssl")
KEYS = Keys("secure")


@pytest.fixture(scope="module")
def profile(tmp_path_factory: pytest.TempPathFactory) -> Iterator[tuple[Path, str]]:
    """A secure profile and its router, running."""
    folder, port = tmp_path_factory.mktemp("secure"), free_port()
    made = catabot("secure", "init", str(folder), "--client", "autopilot", "--observer", "viewer",
                   "--port", str(port))  # fmt: skip
    assert made.returncode == 0, made.stderr
    router = start("router", "--zenoh-config", str(folder / "router.json5"))
    wait_for_line(router, "zenoh router listening")
    try:
        yield folder, f"tls/localhost:{port}"
    finally:
        router.terminate()
        router.wait(timeout=10)


def _scenario(tmp: Path) -> Path:
    imu = {"name": "imu", "type": "imu", "rate_hz": 50.0}
    data = {"name": "secure", "seed": 2, "duration_s": 6.0, "clock": {"realtime_factor": 2.0},
            "vessels": [{"id": "ego", "script": [{"t_s": 0.5, "thrust": [0.5, 0.7]}],
                         "sensors": [imu]}]}  # fmt: skip
    return scenario_file(tmp, data)


def _run(tmp: Path, folder: Path, tag: str, client: str = "") -> dict[str, bytes]:
    """A run through the router; `client` logs in and sends what it should not."""
    out = tmp / tag
    proc = start("run", str(_scenario(tmp)), "--secure", str(folder), "--out", str(out), "--quiet")
    if client:
        conn = Connection(mode="client", file=str(folder / f"{client}.json5"))
        with open_session(conn) as session:
            replies = _set_rain(session, patient=client == "autopilot")
            _going(session)  # physics steps: a command lands inside the run, not before it
            for k in range(20):
                run = "0" * 12
                session.put(KEYS.tick(), codec.encode(Tick(run, k, k * 10**7, 10**7, (), 20)))
                session.put(KEYS.end(), codec.encode(End(run, k, "completed")))
                session.put(KEYS.ack("physics"), codec.encode(Ack(run, 399)))
                session.put(KEYS.cmd_thrust("ego"), codec.encode(ThrustCmd((1.0, -1.0))))
                time.sleep(0.05)
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == 0, err
    if client:  # only a commanding client may change a setting (`catabot set`)
        assert [r.ok is not None for r in replies] == ([True] if client == "autopilot" else [])
    return files_of(only_run_dir(out))


def _going(session: Any, timeout_s: float = 20.0) -> None:
    """Until the run's states come (or `timeout_s`): a thrust put before physics listened, or
    after its last tick, is rightly not recorded (the recorder writes what physics took)."""
    going = threading.Event()
    sub = session.declare_subscriber(KEYS.world_states(), lambda _sample: going.set())
    going.wait(timeout_s)
    sub.undeclare()


def _set_rain(session: Any, *, patient: bool) -> list[Any]:
    """`catabot set rain 50` as a client does it; `patient`: until the conductor's desk
    answers (a query nobody can answer yet returns at once, with nothing)."""
    change = json.dumps({"key": "rain", "value": 50})
    limit = time.monotonic() + (15.0 if patient else 0.0)
    if not patient:
        time.sleep(1.5)  # the desk is up: a refusal is the access control's, not the timing's
    while True:
        replies = list(session.get(KEYS.config("set"), payload=change, timeout=2.0))
        if replies or time.monotonic() > limit:
            return replies
        time.sleep(0.1)


@pytest.mark.parametrize("login", [None, {"user": "viewer", "password": "guessed"}])
def test_no_login_no_connection(
    tmp_path: Path, profile: tuple[Path, str], login: dict[str, str] | None
) -> None:
    folder, _ = profile
    config = json.loads((folder / "viewer.json5").read_text())  # TLS with the profile's CA
    if login is None:
        del config["transport"]["auth"]
    else:
        config["transport"]["auth"]["usrpwd"] = login
    (tmp_path / "intruder.json5").write_text(json.dumps(config))
    with pytest.raises(SessionError):
        open_session(Connection(file=str(tmp_path / "intruder.json5"))).close()


def test_the_profile_holds_its_secrets(profile: tuple[Path, str]) -> None:
    folder, _ = profile
    assert sorted(p.name for p in folder.iterdir() if p.suffix != ".json5") == [
        "ca.key", "ca.pem", "router.key", "router.pem", "users.txt"]  # fmt: skip
    for secret in ("ca.key", "router.key", "users.txt", "viewer.json5", "router.json5"):
        assert (folder / secret).stat().st_mode & 0o077 == 0, secret


def test_bad_names_are_refused(tmp_path: Path) -> None:
    made = catabot("secure", "init", str(tmp_path / "p"), "--client", "physics")
    assert made.returncode == 2 and "names must differ" in made.stderr
    made = catabot("secure", "init", str(tmp_path / "p"), "--observer", "a/b")
    assert made.returncode == 2 and "observer" in made.stderr


def test_an_observer_cannot_drive_the_clock_or_a_vessel(
    tmp_path: Path, profile: tuple[Path, str]
) -> None:
    folder, _ = profile
    clean = _run(tmp_path, folder, "clean")
    attacked = _run(tmp_path, folder, "observer", "viewer")
    assert [name for name in clean if clean[name] != attacked.get(name)] == []
    assert set(attacked) == set(clean)  # the observer's thrust not even recorded


def test_a_commanding_client_commands(tmp_path: Path, profile: tuple[Path, str]) -> None:
    folder, _ = profile
    files = _run(tmp_path, folder, "autopilot", "autopilot")
    rows = files["vessel.ego.cmd.thrust.csv"].decode().splitlines()
    assert any(row.endswith(",1.0,-1.0") for row in rows[1:])  # beside the scripted ones
    # (recorded as physics took it, so sent before the run's last tick: 6 s at 2x gives room)
    assert files["config.changes.csv"].decode().splitlines()[1].endswith(",rain,50.0")


def test_a_process_without_a_login_is_refused_before_anything_starts(
    tmp_path: Path, profile: tuple[Path, str]
) -> None:
    folder, _ = profile
    partial = tmp_path / "partial"
    shutil.copytree(folder, partial)
    (partial / "physics.json5").unlink()
    done = catabot("run", str(_scenario(tmp_path)), "--secure", str(partial), "--out",
                   str(tmp_path / "out"))  # fmt: skip
    assert done.returncode == 2 and "no login for physics" in done.stderr
    assert not (tmp_path / "out").exists()


def test_an_observer_finds_the_world_only_the_conductor_serves(
    tmp_path: Path, profile: tuple[Path, str]
) -> None:
    """Everyone may query `world/info`; a client may not serve one (its queryable is denied,
    so no second answer reaches the observer)."""
    folder, _ = profile
    data = json.loads(_scenario(tmp_path).read_text()) | {"duration_s": 20.0}
    proc = start("run", str(scenario_file(tmp_path, data, "long.json")), "--secure", str(folder),
                 "--out", str(tmp_path / "out"), "--quiet")  # fmt: skip
    try:
        with open_session(Connection(mode="client", file=str(folder / "autopilot.json5"))) as s:
            lie = json.dumps({"v": 1, "world": "secure"})  # refused if it ever arrived
            fake = s.declare_queryable(KEYS.world_info(), lambda q: q.reply(q.key_expr, lie))
            viewer = str(folder / "viewer.json5")
            with Client.connect(mode="client", zenoh_config=viewer, timeout_s=30) as sim:
                assert sim.info.name == "secure" and list(sim.info.vessels["ego"].sensors) == [
                    "imu"
                ]
                assert {"conductor", "physics", "sensors"} <= set(sim.info.roster)
            fake.undeclare()
    finally:
        proc.terminate()
        proc.communicate(timeout=60)


def test_a_profile_for_an_address_connects_there(tmp_path: Path) -> None:
    """`--host 10.9.0.1` wrote the address as a DNS name in the router's certificate, so
    every client was refused, told to start a router that was running."""
    folder, port = tmp_path / "ip", free_port()
    made = catabot("secure", "init", str(folder), "--host", "127.0.0.2", "--port", str(port))
    assert made.returncode == 0, made.stderr
    listen = f"tls/0.0.0.0:{port}"
    router = start("router", "--listen", listen, "--zenoh-config", str(folder / "router.json5"))
    try:
        wait_for_line(router, "zenoh router listening")
        open_session(Connection(file=str(folder / "viewer.json5"))).close()  # IP:127.0.0.2
        wrong = json.loads((folder / "viewer.json5").read_text())
        wrong["connect"]["endpoints"] = [f"tls/127.0.0.3:{port}"]  # an address it does not carry
        (tmp_path / "wrong.json5").write_text(json.dumps(wrong))
        with pytest.raises(SessionError, match="the TLS handshake or the login failed"):
            open_session(Connection(file=str(tmp_path / "wrong.json5"), open_timeout_ms=3000))
    finally:
        router.terminate()
        router.wait(timeout=10)
