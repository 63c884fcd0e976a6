"""`catabot deploy probe`: the health check of a container (compose's `healthcheck`).

Cheap and real, so an engine can run it every few seconds beside a busy simulation:

- `probe ENDPOINT`: the router is up when its port takes a TCP connection and a Zenoh
  client session opens there (an open port alone was any program's: an HTTP server passed).
- `probe ENDPOINT --http`: a web server (the viewer's) is up when it answers an HTTP request
  there (a Zenoh handshake never passed it).
- `probe ENDPOINT --name physics`: a CataBot process is healthy once it is on the bus,
  i.e. its liveliness token `catabot/<world>/live/physics/<zid>` is there (declared when it
  joined: catabot/bus/participant.py; gone when it ends or crashes). One short Zenoh client
  session asks the router; with `--zenoh-config` it logs in as the secure profile says.

Exit 0 healthy, 1 not (one line says why). This module imports only the bus's session
code: a probe costs a Python start-up and one session, not the simulation's imports.
"""

from __future__ import annotations

import argparse
import socket
import sys

from catabot.bus.keys import lives_of
from catabot.bus.session import Connection, dial_address, open_session, port_open
from catabot.errors import CataBotError
from catabot.run.answer import OneLineParser

TIMEOUT_S = 3.0


def parser() -> argparse.ArgumentParser:
    p = OneLineParser(prog="catabot deploy probe", description=__doc__.split("\n")[0])
    p.add_argument("endpoint", help="the router's endpoint, e.g. tcp/router:7447")
    what = p.add_mutually_exclusive_group()
    what.add_argument("--name", help="a process that must be on the bus (its liveliness token)")
    what.add_argument("--http", action="store_true", help="a web server, not Zenoh, answers there")
    p.add_argument("--zenoh-config", metavar="FILE", help="a login of the secure profile")
    return p


def _client(endpoint: str, config: str | None) -> Connection:
    limit = round(TIMEOUT_S * 1000)  # a silent listener held the handshake 10 s
    return Connection(connect=(endpoint,), mode="client", file=config, open_timeout_ms=limit)


def speaks_zenoh(endpoint: str, config: str | None) -> None:
    """SessionError unless a Zenoh session opens there: an open port alone was any
    program's (an HTTP server passed for a healthy router)."""
    open_session(_client(endpoint, config)).close()


def answers_http(endpoint: str, timeout_s: float = TIMEOUT_S) -> str:
    """'' when an HTTP server answers a request at the endpoint, else why not."""
    try:
        with socket.create_connection(dial_address(endpoint), timeout=timeout_s) as conn:
            conn.sendall(b"GET / HTTP/1.0\r\nHost: probe\r\n\r\n")
            head = conn.recv(16)
    except TimeoutError:
        head = b""  # it took the connection and said nothing (a Zenoh node waits so)
    except (OSError, ValueError) as exc:
        return f"{endpoint}: {exc}"
    return "" if head.startswith(b"HTTP/") else f"{endpoint}: takes connections but not as HTTP"


def on_bus(endpoint: str, name: str, config: str | None, timeout_s: float = TIMEOUT_S) -> str:
    """'' when a liveliness token of `name` (in any world on this router) answers."""
    key = lives_of(name)
    session = open_session(_client(endpoint, config))
    try:
        replies = session.liveliness().get(key, timeout=timeout_s)
        if any(reply.ok is not None for reply in replies):
            return ""
        return f"{name} has no liveliness token on {endpoint} (not joined, or gone)"
    finally:
        session.close()


def main(argv: list[str] | None = None) -> int:
    args = parser().parse_args(argv)
    try:
        why = port_open(args.endpoint, TIMEOUT_S)
        if not why and args.http:
            why = answers_http(args.endpoint)
        elif not why and args.name:
            why = on_bus(args.endpoint, args.name, args.zenoh_config)
        elif not why:
            speaks_zenoh(args.endpoint, args.zenoh_config)
    except CataBotError as exc:  # a bad endpoint, name or login file
        why = str(exc)
    if why:
        print(f"unhealthy: {why}", file=sys.stderr)
        return 1
    print(f"healthy: {args.name or args.endpoint}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
