"""Opening Zenoh sessions, one way for every program (services, CLI, examples).

The embedded default is peer-to-peer on loopback with multicast scouting off: the
launcher's conductor listens on a free port, every service connects to it, and gossip
completes the mesh so data flows peer to peer. For several machines, point every
program at a router with `--connect tcp/HOST:7447` (see `catabot router`).
"""

from __future__ import annotations

import argparse
import json
import os
import random
import re
import socket
import time
from collections.abc import Callable, Sized
from dataclasses import dataclass
from pathlib import Path
from typing import TypeVar

import zenoh

from catabot.bus import tls
from catabot.bus.identity import check_zid
from catabot.errors import CataBotError

MODES = ("peer", "client", "router")
LEASE_MS = 1500
OPEN_TIMEOUT_MS = 2000  # a handshake's limit (_embedded says why)
FIRST_PORT = 20000  # free_port draws from here to the ephemeral range: above the well-known
LOOPBACK = "tcp/127.0.0.1:0"
RETRY = "{period_init_ms: 250, period_max_ms: 1000, period_increase_factor: 2}"  # connect
ASK_AGAIN_S = 0.2  # between two queries nobody answered (until_answered)
UNKNOWN_HOST = "its host name is not known here"  # port_open, _why_unreachable
A = TypeVar("A", bound=Sized)  # a batch of answers: empty when nobody answered
BLOCK = zenoh.CongestionControl.BLOCK  # lockstep data and clock messages are never dropped


class SessionError(CataBotError, RuntimeError):
    """Zenoh could not be opened with the given endpoints."""


@dataclass(frozen=True)
class Connection:
    """Where a program's Zenoh session listens and what it connects to.

    `file` (or the ZENOH_CONFIG environment variable) is a Zenoh config file (JSON5): TLS,
    credentials, a router's access control (the secure profile: deploy/secure/). With one,
    CataBot changes only what its flags set (mode, connect, listen, zid); without one, the
    embedded defaults: peer mode on loopback, no multicast scouting, a 1.5 s link lease."""

    connect: tuple[str, ...] = ()
    listen: tuple[str, ...] = ()  # none given: tcp/127.0.0.1:0 in peer mode, without a file
    mode: str | None = None  # None: the file's, else peer
    zid: str | None = None  # this session's id (catabot run picks one per process); None: random
    file: str | None = None
    timestamping: bool = False  # Zenoh's advanced publishers (a cache for late joiners) need it
    open_timeout_ms: int | None = None  # a handshake's limit (Zenoh's 10 s: a silent listener)

    def config(self) -> zenoh.Config:
        if self.mode is not None and self.mode not in MODES:
            raise SessionError(f"zenoh mode {self.mode!r} is not one of {', '.join(MODES)}")
        for endpoint in (*self.connect, *self.listen):
            check_endpoint(endpoint)
        path = self.file or os.environ.get("ZENOH_CONFIG") or None
        cfg = _from_file(path) if path else _embedded(self.mode or "peer")
        if self.mode is not None:
            cfg.insert_json5("mode", json.dumps(self.mode))
        if self.connect:
            cfg.insert_json5("connect/endpoints", json.dumps(list(self.connect)))
        if self.listen or (self.mode == "client" and not path):
            listen = [] if self.mode == "client" else list(self.listen)
            cfg.insert_json5("listen/endpoints", json.dumps(listen))
        if self.zid is not None:
            cfg.insert_json5("id", json.dumps(check_zid(self.zid)))
        if self.timestamping:
            cfg.insert_json5("timestamping/enabled", "true")
        if self.open_timeout_ms is not None:
            cfg.insert_json5("transport/unicast/open_timeout", str(self.open_timeout_ms))
        return cfg

    def described(self) -> str:
        return _described(self.config())


def _embedded(mode: str) -> zenoh.Config:
    cfg = zenoh.Config()
    cfg.insert_json5("mode", json.dumps(mode))
    cfg.insert_json5("scouting/multicast/enabled", "false")
    cfg.insert_json5("connect/endpoints", "[]")
    cfg.insert_json5("listen/endpoints", json.dumps([] if mode == "client" else [LOOPBACK]))
    # A peer that stops answering (a stopped process, a cut link) is gone within 2 s, not
    # Zenoh's default 10 s: keep-alives every 0.375 s, a lease of 1.5 s (a cut cable is named
    # 1.6-1.9 s after the cut across six hosts, tests/e2e/test_distributed.py).
    cfg.insert_json5("transport/link/tx/lease", str(LEASE_MS))
    cfg.insert_json5("transport/link/tx/keep_alive", "4")
    # A program started before the one it connects to (a client before `catabot run`, a
    # service before the conductor listens) tries again every 0.25 s, at most 1 s apart:
    # Zenoh's default backs off to 4 s, and a short run could end before it joined
    # (measured: 1.5 s late after a 5 s wait with the default, 0.3 s with this).
    cfg.insert_json5("connect/retry", RETRY)
    # A handshake's limit: Zenoh's 10 s held `session.close()` that long once a link had
    # gone silent (its reconnect attempt, unanswered, must time out first): a cut cable
    # left every process of a run alive 11.5 s after it had flushed its files (0.5-0.8 s
    # with 1-2 s). A TLS handshake and login take well under 1 s, even between continents.
    cfg.insert_json5("transport/unicast/open_timeout", str(OPEN_TIMEOUT_MS))
    return cfg


def _from_file(path: str) -> zenoh.Config:
    if not Path(path).is_file():
        raise SessionError(f"zenoh config file {path!r} does not exist")
    try:
        config = zenoh.Config.from_file(path)
    except Exception as exc:
        raise SessionError(f"zenoh config file {path}: {exc}") from None
    if missing := tls.missing_file(config):
        raise SessionError(f"zenoh config file {path}: {missing}")
    return config


_ENDPOINT = re.compile(r"^(tcp|udp|tls|quic|ws)/(\[[0-9a-fA-F:.]+\]|[A-Za-z0-9_.\-]+):(\d{1,5})$")


def check_endpoint(endpoint: str) -> str:
    """A Zenoh endpoint `proto/host:port` (tcp, udp, tls, quic, ws), refused with a clear
    message before any process starts (Zenoh's own error comes from deep inside, late)."""
    m = _ENDPOINT.match(endpoint)
    if m is None or int(m.group(3)) > 65535:
        raise SessionError(
            f"zenoh endpoint {endpoint!r}: use proto/host:port with proto tcp, udp, tls, quic "
            "or ws, e.g. tcp/127.0.0.1:7447"
        )
    return endpoint


def check_listen(endpoint: str) -> None:
    """A TCP endpoint this machine can listen on now: its host is one of this machine's
    addresses and its port is free. Zenoh says so only once every process has started."""
    host, port = _tcp(endpoint)
    if host is None:
        return
    family, addr = _address(endpoint, host, port)
    with socket.socket(family, socket.SOCK_STREAM) as probe:
        probe.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)  # as a listener does
        try:
            probe.bind(addr)
        except OSError as exc:
            raise SessionError(f"cannot listen on {endpoint}: {exc.strerror or exc}") from None


def check_router(endpoint: str) -> None:
    """Something answers at a TCP endpoint to connect to: a client session fails at once
    when nothing does, so every process would start only to fail."""
    host, port = _tcp(endpoint)
    if host is None:
        return
    family, addr = _address(endpoint, host, port)
    with socket.socket(family, socket.SOCK_STREAM) as probe:
        probe.settimeout(3.0)
        try:
            probe.connect(addr)
        except OSError as exc:
            raise SessionError(
                f"nothing answers at {endpoint} ({exc.strerror or exc}): start a router there "
                "first (catabot router --listen ENDPOINT), or the run that listens there "
                "(catabot run --listen ENDPOINT)"
            ) from None


def _tcp(endpoint: str) -> tuple[str | None, int]:
    """Host and port of a plain TCP endpoint; None for the others (TLS, UDP, QUIC, WS: a
    bare socket probe would not speak their handshake)."""
    m = _ENDPOINT.match(check_endpoint(endpoint))
    assert m is not None, "check_endpoint matched it"
    return (m.group(2).strip("[]") if m.group(1) == "tcp" else None), int(m.group(3))


def _address(endpoint: str, host: str, port: int) -> tuple[socket.AddressFamily, tuple[str, int]]:
    try:
        family, _, _, _, addr = socket.getaddrinfo(host, port, type=socket.SOCK_STREAM)[0]
    except socket.gaierror:
        raise SessionError(f"zenoh endpoint {endpoint}: host {host!r} is not known") from None
    return family, (str(addr[0]), int(addr[1]))


def until_answered(ask: Callable[[float], A], timeout_s: float) -> A:
    """`ask(seconds)` again, each wait at most 2 s, until it answers something or
    `timeout_s` is over (a run just starting has no queryable yet); its last answer."""
    limit = time.monotonic() + timeout_s
    while True:
        answers = ask(max(min(limit - time.monotonic(), 2.0), 0.1))
        if answers or time.monotonic() >= limit:
            return answers
        time.sleep(ASK_AGAIN_S)


def open_session(conn: Connection) -> zenoh.Session:
    config = conn.config()
    try:
        return zenoh.open(config)
    except Exception as exc:
        said = re.sub(r"\s+at \S+\.rs:\d+\.?", "", str(exc).strip())  # Zenoh's source line
        if "Unable to connect" in said:  # the endpoints a config file names too
            said += _why_unreachable(_endpoints(config, "connect"))
        raise SessionError(
            f"cannot open zenoh ({_described(config)}, listen {[*_endpoints(config, 'listen')]}, "
            f"config {conn.file or os.environ.get('ZENOH_CONFIG')}): {said}"
        ) from None


def _described(config: zenoh.Config) -> str:
    """Where a session connects and in which mode, a config file's own settings included
    (the flags alone said "connect none, mode peer" of a file's client on tls/...)."""
    mode = json.loads(config.get_json("mode"))
    return f"connect {list(_endpoints(config, 'connect')) or 'none'}, mode {mode}"


def _endpoints(config: zenoh.Config, kind: str) -> tuple[str, ...]:
    """The endpoints a session connects to or listens on (`kind`), in CataBot's plain form
    (a router's error said "listen []" of its file's endpoints): a config file may
    give them per mode (`{client: [...], peer: [...]}`) or with `#`/`?` metadata, which a
    probe skips rather than fail on while it explains another failure."""
    found = json.loads(config.get_json(f"{kind}/endpoints"))
    if isinstance(found, dict):
        found = [e for v in found.values() if isinstance(v, list) for e in v]
    return tuple(e for e in found if isinstance(e, str) and _ENDPOINT.match(e))


def _why_unreachable(endpoints: tuple[str, ...]) -> str:
    """A port that takes a TCP connection but no Zenoh handshake is another program's (an
    HTTP server, a TLS endpoint given as tcp/): "start a router" sent people the wrong way."""
    said = {e: port_open(e, 1.0) for e in endpoints}  # one probe each (up to 1 s)
    taken = [e for e in endpoints if _tcp(e)[0] is not None and not said[e]]
    if taken:
        return (f" ({', '.join(taken)} takes connections but does not answer as Zenoh: "
                "another program listens there, or it wants tls/)")  # fmt: skip
    secured = [e for e in endpoints if e.startswith("tls/") and not said[e]]
    if secured:  # a secure router is there: its certificate or the login was refused
        return (f" ({', '.join(secured)} takes connections, but the TLS handshake or the "
                "login failed: the router's certificate must be signed by your ca.pem, be in "
                "date and name the host you connect to, an address included (catabot secure "
                "init --host); the login must be one of its profile's)")  # fmt: skip
    if unknown := [e for e in endpoints if said[e].endswith(UNKNOWN_HOST)]:
        return f" ({', '.join(unknown)}: {UNKNOWN_HOST})"
    return " (nothing answers there: start a router first, catabot router --listen ...)"


def port_open(endpoint: str, timeout_s: float = 3.0) -> str:
    """'' when the endpoint's TCP port takes a connection, else why not (any protocol: a
    TLS port is probed the same way). A listening address (0.0.0.0, [::]) is probed on this
    host's loopback."""
    try:
        with socket.create_connection(dial_address(endpoint), timeout=timeout_s):
            return ""
    except socket.gaierror:  # not "nothing answers there: start a router"
        return f"{endpoint}: {UNKNOWN_HOST}"
    except OSError as exc:
        return f"{endpoint}: {exc.strerror or exc}"


def dial_address(endpoint: str) -> tuple[str, int]:
    """The (host, port) a socket connects to for an endpoint of any protocol, a listening
    address (0.0.0.0, [::]) meaning this host's loopback."""
    host, _, port = check_endpoint(endpoint).partition("/")[2].rpartition(":")
    host = host.strip("[]")
    return {"0.0.0.0": "127.0.0.1", "::": "::1"}.get(host, host), int(port)


def linked(session: zenoh.Session) -> bool:
    """Whether the session reaches another Zenoh node now (a router or a peer)."""
    return bool(list(session.info.routers_zid()) or list(session.info.peers_zid()))


def alone(session: zenoh.Session) -> str:
    """A note for a process that waits for others while its session reaches no other Zenoh
    node (a peer told to --connect where nobody listens retries quietly forever), else ""."""
    if linked(session):
        return ""
    return ("; this process reaches no other Zenoh node: is anything listening where it "
            "connects? (to a router, give --mode client: it then fails at once)")  # fmt: skip


def free_port() -> int:
    """A TCP port that is free on loopback now (the embedded conductor listens on it), below
    the kernel's ephemeral range: a port from bind(0) lies in that range, where any outgoing
    connection may take it before the listener binds it (a CI run's test lost a run to
    "Address already in use" so). Drawn at random, each tried; bind(0) if none is free."""
    low = _ephemeral_low()
    for port in random.Random().sample(range(FIRST_PORT, low), k=min(64, low - FIRST_PORT)):
        with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
            try:
                s.bind(("127.0.0.1", port))
            except OSError:
                continue
            return port
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def _ephemeral_low() -> int:
    """The lowest port the kernel gives outgoing connections (Linux; 32768 elsewhere)."""
    try:
        low = int(Path("/proc/sys/net/ipv4/ip_local_port_range").read_text().split()[0])
    except (OSError, ValueError, IndexError):
        return 32768
    return max(low, FIRST_PORT + 1)


def add_connection_args(parser: argparse.ArgumentParser, *, router: bool = False) -> None:
    """The connection flags every CataBot program shares; a router has no --mode (it is one:
    `catabot router --mode peer` was taken and ignored) and listens on 7447 by default."""
    parser.add_argument(
        "--connect",
        "-e",
        action="append",
        default=[],
        metavar="ENDPOINT",
        help="zenoh endpoint to connect to, e.g. tcp/192.168.1.10:7447 (repeatable)",
    )
    parser.add_argument(
        "--listen",
        "-l",
        action="append",
        default=[],
        metavar="ENDPOINT",
        help="zenoh endpoint to listen on (default "
        + ("tcp/127.0.0.1:7447)" if router else "tcp/127.0.0.1:0 in peer mode)"),
    )
    if not router:
        parser.add_argument("--mode", choices=MODES, help="zenoh session mode (default: peer)")
    parser.add_argument("--zid", help="this session's Zenoh id (hex; default: random)")
    parser.add_argument(
        "--zenoh-config",
        metavar="FILE",
        help="a Zenoh config file (TLS, credentials; default: $ZENOH_CONFIG, if set)",
    )


def connection_from_args(args: argparse.Namespace) -> Connection:
    return Connection(
        connect=tuple(args.connect),
        listen=tuple(args.listen),
        mode=args.mode,
        zid=args.zid,
        file=args.zenoh_config,
    )
