"""The one way every example parses its connection flags and opens Zenoh."""

from __future__ import annotations

import argparse
from collections.abc import Iterator
from contextlib import contextmanager

import zenoh

from catabot.bus.keys import Keys
from catabot.bus.session import add_connection_args, connection_from_args, open_session
from catabot.client import ClientError


def parser(description: str | None) -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        description=description, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    add_connection_args(p)
    p.add_argument(
        "--world", help="scenario name (key prefix catabot/<world>; default: the one running)"
    )
    p.add_argument("--vessel", default="ego", help="vessel id")
    p.add_argument(
        "--participant", help="lockstep name (default: the vessel's controller.participant)"
    )
    p.add_argument("--timeout", type=float, default=30.0, help="seconds to wait for the run")
    return p


def session(args: argparse.Namespace) -> zenoh.Session:
    return open_session(connection_from_args(args))


def keys(args: argparse.Namespace) -> Keys:
    """The keys of `--world` (the bundled `default` scenario when not given)."""
    return Keys(args.world or "default")


@contextmanager
def clear_errors(program: str) -> Iterator[None]:
    """A client's error (no simulation, no such vessel or sensor, the run ended...) ends the
    program with its message, not a traceback."""
    try:
        yield
    except ClientError as e:
        raise SystemExit(f"{program}: {e}") from None
