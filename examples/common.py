"""The one way every example parses its connection flags and opens Zenoh."""

from __future__ import annotations

import argparse

import zenoh

from catabot.bus.session import add_connection_args, connection_from_args, open_session


def parser(description: str | None) -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        description=description, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    add_connection_args(p)
    p.add_argument("--world", default="default", help="scenario name (key prefix catabot/<world>)")
    p.add_argument("--vessel", default="ego", help="vessel id")
    return p


def session(args: argparse.Namespace) -> zenoh.Session:
    return open_session(connection_from_args(args))
