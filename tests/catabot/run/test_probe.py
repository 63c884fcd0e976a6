"""The containers' health probe (`catabot deploy probe`) and the conductor's flags for them:
`--start-timeout` (a participant that never joins is named, exit 1) and `--linger` (the
conductor's container ends only once every participant has left)."""

from __future__ import annotations

import http.server
import json
import signal
import socket
import subprocess
import sys
import threading
import time
from collections.abc import Iterator

import pytest
import zenoh

from catabot.bus.session import Connection, free_port, open_session
from catabot.run import probe
from tests.paths import REPO


@pytest.fixture
def bus() -> Iterator[tuple[str, zenoh.Session]]:
    """A Zenoh peer listening on a free port (what the probe connects to, as to a router)."""
    endpoint = f"tcp/127.0.0.1:{free_port()}"
    session = open_session(Connection(listen=(endpoint,)))
    try:
        yield endpoint, session
    finally:
        session.close()


def test_a_port_is_open_while_something_listens() -> None:
    with socket.create_server(("127.0.0.1", 0)) as server:
        port = server.getsockname()[1]
        assert probe.port_open(f"tcp/127.0.0.1:{port}") == ""
        assert probe.port_open(f"tls/0.0.0.0:{port}") == ""  # a listening address: loopback
    assert f"tcp/127.0.0.1:{port}" in probe.port_open(f"tcp/127.0.0.1:{port}")


def test_a_process_is_healthy_while_its_token_is_on_the_bus(
    bus: tuple[str, zenoh.Session], capsys: pytest.CaptureFixture[str]
) -> None:
    endpoint, session = bus
    token = session.liveliness().declare_token(f"catabot/w/live/physics/{session.zid()}")
    assert probe.main([endpoint, "--name", "physics"]) == 0
    assert probe.main([endpoint, "--name", "sensors"]) == 1
    assert "sensors has no liveliness token" in capsys.readouterr().err
    token.undeclare()
    time.sleep(0.3)
    assert probe.main([endpoint, "--name", "physics"]) == 1


def test_bad_probes_say_why(capsys: pytest.CaptureFixture[str]) -> None:
    assert probe.main(["tcp/nowhere"]) == 1
    assert "use proto/host:port" in capsys.readouterr().err
    with socket.create_server(("127.0.0.1", 0)) as server:
        endpoint = f"tcp/127.0.0.1:{server.getsockname()[1]}"
        assert probe.main([endpoint, "--name", "a/*"]) == 1
    assert "participant" in capsys.readouterr().err


def test_the_conductor_names_who_never_joined_and_lingers_for_who_did(
    bus: tuple[str, zenoh.Session],
) -> None:
    """physics joins (its token), sensors and the recorder never do: after --start-timeout
    the conductor names them and ends with 1, but only once physics has left (--linger)."""
    endpoint, session = bus
    token = session.liveliness().declare_token(f"catabot/default/live/physics/{session.zid()}")
    command = [sys.executable, "-m", "catabot.run.conduct", "--connect", endpoint,
               "--start-timeout", "1", "--linger", "30"]  # fmt: skip
    proc = subprocess.Popen(command, cwd=REPO, stdout=subprocess.PIPE, text=True)
    try:
        assert proc.stdout is not None
        result = next(json.loads(line) for line in proc.stdout if '"result"' in line)
        assert "never joined within 1 s: recorder, sensors" in result["error"]
        time.sleep(1.0)
        assert proc.poll() is None  # physics is still on the bus
        token.undeclare()
        assert proc.wait(timeout=10) == 1
    finally:
        proc.kill()
        proc.wait()


def test_the_conductor_refuses_bad_seconds() -> None:
    command = [sys.executable, "-m", "catabot.run.conduct", "--start-timeout", "-1"]
    done = subprocess.run(command, cwd=REPO, capture_output=True, text=True, timeout=60)
    assert done.returncode == 2 and "more than 0" in done.stderr


def test_the_router_ends_at_once_on_sigterm() -> None:
    """`docker stop` / `compose down` send SIGTERM; as a container's PID 1 a process without
    a handler would ignore it and be killed 10 s later."""
    endpoint = f"tcp/127.0.0.1:{free_port()}"
    command = [sys.executable, "-m", "catabot", "router", "--listen", endpoint]
    proc = subprocess.Popen(command, cwd=REPO, stdout=subprocess.PIPE, text=True)
    try:
        assert proc.stdout is not None and "listening" in proc.stdout.readline()
        assert probe.port_open(endpoint) == ""
        proc.send_signal(signal.SIGTERM)
        assert proc.wait(timeout=5) == 0
    finally:
        proc.kill()
        proc.wait()


def test_a_router_probe_needs_zenoh_not_an_open_port(capsys: pytest.CaptureFixture[str]) -> None:
    """Any program on the router's port passed (an operator's HTTP server): the probe now
    opens a Zenoh session there, within its 3 s, even against a listener that never answers."""
    with socket.create_server(("127.0.0.1", 0)) as server:
        endpoint = f"tcp/127.0.0.1:{server.getsockname()[1]}"
        start = time.monotonic()
        assert probe.main([endpoint]) == 1
        assert time.monotonic() - start < probe.TIMEOUT_S + 2.0
    said = capsys.readouterr().err
    assert f"{endpoint} takes connections but does not answer as Zenoh" in said, said


def test_a_router_probe_passes_on_a_zenoh_node(
    bus: tuple[str, zenoh.Session], capsys: pytest.CaptureFixture[str]
) -> None:
    endpoint, _ = bus
    assert probe.main([endpoint]) == 0
    assert f"healthy: {endpoint}" in capsys.readouterr().out


def test_a_web_probe_needs_an_http_answer(
    bus: tuple[str, zenoh.Session], capsys: pytest.CaptureFixture[str]
) -> None:
    """The viewer's health check opened a Zenoh session on its web port, so it never passed."""
    web = http.server.ThreadingHTTPServer(("127.0.0.1", 0), http.server.SimpleHTTPRequestHandler)
    thread = threading.Thread(target=web.serve_forever, daemon=True)
    thread.start()
    try:
        assert probe.main([f"tcp/127.0.0.1:{web.server_address[1]}", "--http"]) == 0
    finally:
        web.shutdown()
        web.server_close()
    endpoint, _ = bus  # a Zenoh node is no web server
    assert probe.main([endpoint, "--http"]) == 1
    assert "takes connections but not as HTTP" in capsys.readouterr().err
