"""Opening Zenoh sessions, one way for every program (services, CLI, examples).

The embedded default is peer-to-peer on loopback with multicast scouting off: the
launcher's conductor listens on a free port, every service connects to it, and gossip
completes the mesh so data flows peer to peer. For several machines, point every
program at a router with `--connect tcp/HOST:7447` (see `catabot router`).
"""

from __future__ import annotations

import argparse
import json
import socket
from collections.abc import Sequence
from dataclasses import dataclass, field

import zenoh

from catabot.bus.identity import check_zid
from catabot.errors import CataBotError

MODES = ("peer", "client", "router")
LEASE_MS = 2000
BLOCK = zenoh.CongestionControl.BLOCK  # lockstep data and clock messages are never dropped


class SessionError(CataBotError, RuntimeError):
    """Zenoh could not be opened with the given endpoints."""


@dataclass(frozen=True)
class Connection:
    """Where a program's Zenoh session listens and what it connects to."""

    connect: tuple[str, ...] = ()
    listen: tuple[str, ...] = field(default_factory=lambda: ("tcp/127.0.0.1:0",))
    mode: str = "peer"
    zid: str | None = None  # this session's id (catabot run picks one per process); None: random

    def config(self) -> zenoh.Config:
        if self.mode not in MODES:
            raise SessionError(f"zenoh mode {self.mode!r} is not one of {', '.join(MODES)}")
        cfg = zenoh.Config()
        cfg.insert_json5("mode", json.dumps(self.mode))
        cfg.insert_json5("scouting/multicast/enabled", "false")
        cfg.insert_json5("connect/endpoints", json.dumps(list(self.connect)))
        listen = [] if self.mode == "client" else list(self.listen)
        cfg.insert_json5("listen/endpoints", json.dumps(listen))
        if self.zid is not None:
            cfg.insert_json5("id", json.dumps(check_zid(self.zid)))
        # A peer that stops answering (a stopped process, a cut link) is gone after 2 s,
        # not Zenoh's default 10 s: keep-alives every 0.5 s.
        cfg.insert_json5("transport/link/tx/lease", str(LEASE_MS))
        cfg.insert_json5("transport/link/tx/keep_alive", "4")
        return cfg


def open_session(conn: Connection) -> zenoh.Session:
    try:
        return zenoh.open(conn.config())
    except Exception as exc:
        raise SessionError(
            f"cannot open zenoh (mode {conn.mode}, connect {list(conn.connect)}, "
            f"listen {list(conn.listen)}): {exc}"
        ) from None


def free_port() -> int:
    """A TCP port that is free on loopback now (the embedded conductor listens on it)."""
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def add_connection_args(parser: argparse.ArgumentParser) -> None:
    """The connection flags every CataBot program shares."""
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
        help="zenoh endpoint to listen on (default tcp/127.0.0.1:0 in peer mode)",
    )
    parser.add_argument("--mode", choices=MODES, default="peer", help="zenoh session mode")
    parser.add_argument("--zid", help="this session's Zenoh id (hex; default: random)")


def connection_from_args(args: argparse.Namespace) -> Connection:
    listen: Sequence[str] = args.listen or ("tcp/127.0.0.1:0",)
    return Connection(
        connect=tuple(args.connect), listen=tuple(listen), mode=args.mode, zid=args.zid
    )
