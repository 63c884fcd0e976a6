"""The one way every example parses its connection flags and opens Zenoh."""

from __future__ import annotations

import argparse
from collections.abc import Iterator
from contextlib import contextmanager

import zenoh

from catabot.bus.keys import Keys
from catabot.bus.session import connection_from_args, open_session
from catabot.client import End, add_stack_args
from catabot.client.discover import find_world
from catabot.errors import CataBotError


def parser(description: str | None) -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        description=description, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    add_stack_args(p)  # the connection, --world, --vessel, --participant, --timeout
    return p


def session(args: argparse.Namespace) -> zenoh.Session:
    return open_session(connection_from_args(args))


def keys(s: zenoh.Session, args: argparse.Namespace) -> Keys:
    """The keys of `--world`, or of the one world running, once it answers (waiting up to
    `--timeout`); ends the program naming the vessels if `--vessel` is not one of them."""
    with clear_errors("catabot example"):
        info = find_world(s, args.world, args.timeout, " ".join(args.connect) or "peer mesh")
    bodies = [*info.vessels, *info.traffic]
    if args.vessel not in bodies:
        vessels, boats = ", ".join(info.vessels), len(info.traffic)
        raise SystemExit(
            f"world {info.name!r} has no vessel {args.vessel!r}; its vessels: {vessels} "
            f"(and {boats} traffic boats)"
        )
    return Keys(info.name)


@contextmanager
def clear_errors(program: str) -> Iterator[None]:
    """A client's error (no simulation, no such vessel or sensor, the run ended, a malformed
    --connect...) ends the program with its message, and Ctrl-C with exit 130, not a
    traceback."""
    try:
        yield
    except CataBotError as e:
        raise SystemExit(f"{program}: {e}") from None
    except KeyboardInterrupt:
        raise SystemExit(130) from None


def report(end: End | None, text: str) -> None:
    """How the run ended, then `text`; a run that ended in a fault exits 1 with the fault's
    words, as `catabot run` does (a stack printed "(fault)" and exited 0)."""
    print(f"{'stopped' if end is None else f'run ended at tick {end.tick} ({end.reason})'}; {text}")
    if end is not None and end.error:
        raise SystemExit(f"the run's fault: {end.error}")
