"""The endpoint probes `catabot run` makes before it starts anything (catabot/bus/session.py):
Zenoh itself would fail only inside every process, after all of them had started."""

from __future__ import annotations

import json
import socket
import time
from pathlib import Path

import pytest

from catabot.bus import session
from catabot.bus.session import (
    Connection,
    SessionError,
    alone,
    check_listen,
    check_router,
    free_port,
    open_session,
)


def test_a_free_loopback_port_can_be_listened_on() -> None:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    check_listen(f"tcp/127.0.0.1:{port}")


def test_an_address_of_another_machine_cannot_be_listened_on() -> None:
    with pytest.raises(SessionError, match=r"on tcp/192\.0\.2\.1:7447: Cannot assign"):
        check_listen("tcp/192.0.2.1:7447")


def test_an_unknown_host_is_named() -> None:
    for check in (check_listen, check_router):
        with pytest.raises(SessionError, match=r"host 'no-such-host\.invalid' is not known"):
            check("tcp/no-such-host.invalid:7447")


def test_a_router_is_found_where_something_listens() -> None:
    with socket.socket() as server:
        server.bind(("127.0.0.1", 0))
        server.listen()
        check_router(f"tcp/127.0.0.1:{server.getsockname()[1]}")
        with pytest.raises(SessionError, match="Address already in use"):
            check_listen(f"tcp/127.0.0.1:{server.getsockname()[1]}")


def test_other_protocols_are_left_to_zenoh_but_their_syntax_is_checked() -> None:
    check_router("tls/127.0.0.1:1")  # a bare socket would not speak TLS: not probed
    check_listen("udp/192.0.2.1:7447")
    with pytest.raises(SessionError, match="use proto/host:port"):
        check_router("garbage")


def test_a_session_that_reaches_nobody_is_told_so_and_one_that_does_is_not() -> None:
    """A peer told to --connect where nobody listens retries quietly forever: its "no tick
    yet" lines now say that it reaches no other node."""
    port = free_port()
    lonely = open_session(Connection(connect=(f"tcp/127.0.0.1:{port}",)))
    try:
        assert "reaches no other Zenoh node" in alone(lonely)
        other = open_session(Connection(listen=(f"tcp/127.0.0.1:{port}",)))
        try:
            deadline = time.monotonic() + 10.0
            while alone(lonely) and time.monotonic() < deadline:
                time.sleep(0.1)  # it connects on its next retry (at most 1 s apart)
            assert alone(lonely) == ""
        finally:
            other.close()
    finally:
        lonely.close()


def test_a_free_port_lies_below_the_kernels_ephemeral_range() -> None:
    """bind(0)'s ports are the ones outgoing connections take: one did, between a test's
    pick and its run's bind ("Address already in use")."""
    low = session._ephemeral_low()
    ports = {session.free_port() for _ in range(20)}
    assert all(session.FIRST_PORT <= p < low for p in ports), ports
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind(("127.0.0.1", ports.pop()))  # free indeed


def test_a_config_files_endpoints_are_read_in_either_form(tmp_path: Path) -> None:
    """Zenoh's per-mode form in a file raised "zenoh endpoint 'peer': use proto/host:port"
    from inside the explanation of a plain "nobody listens there"."""
    port = free_port()
    config = {"mode": "client", "connect": {"endpoints": {"client": [f"tcp/127.0.0.1:{port}"],
                                                          "peer": []}}}  # fmt: skip
    (tmp_path / "z.json5").write_text(json.dumps(config))
    with pytest.raises(SessionError, match="nothing answers there"):
        open_session(Connection(file=str(tmp_path / "z.json5"), open_timeout_ms=500))


def test_a_connection_is_described_with_its_config_files_settings(tmp_path: Path) -> None:
    """A stack given a secure profile's config file was told it had tried "connect none,
    mode peer", and advised to listen on tcp/: the file's client mode and tls/ endpoint."""
    config = tmp_path / "autopilot.json5"
    config.write_text('{mode: "client", connect: {endpoints: ["tls/127.0.0.1:7447"]}}')
    assert Connection(file=str(config)).described() == (
        "connect ['tls/127.0.0.1:7447'], mode client"
    )
    assert Connection().described() == "connect none, mode peer"


def test_a_tls_file_the_config_names_that_is_not_there_is_named(tmp_path: Path) -> None:
    """A missing ca.pem was reported as a failed TLS handshake or login."""
    tls = {"root_ca_certificate": str(tmp_path / "ca.pem")}
    config = {"mode": "client", "connect": {"endpoints": ["tls/localhost:7449"]},
              "transport": {"link": {"tls": tls}}}  # fmt: skip
    (tmp_path / "c.json5").write_text(json.dumps(config))
    with pytest.raises(SessionError, match=r"root_ca_certificate .*ca\.pem does not exist"):
        open_session(Connection(file=str(tmp_path / "c.json5")))


def test_a_host_name_not_known_is_said_so() -> None:
    """It was told to start a router there."""
    endpoint = "tls/nosuchhost.invalid:7462"
    assert session.port_open(endpoint, 1.0) == f"{endpoint}: its host name is not known here"
    assert "host name is not known" in session._why_unreachable((endpoint,))
