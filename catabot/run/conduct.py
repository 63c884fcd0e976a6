"""`catabot conductor`: the conductor as a program; progress as JSON lines on stdout.

The launcher reads those lines to draw its progress bar; on another machine the same
program runs alone against a router.
"""

from __future__ import annotations

import argparse
import json
import logging
import os
import signal
import sys
import threading
import time
from dataclasses import asdict
from typing import NoReturn

import zenoh

from catabot.bus.blas import single_thread_blas
from catabot.bus.clock import LAUNCHER_GONE, Policy
from catabot.bus.conductor import ClockSpec, Conductor, Progress
from catabot.bus.heap import keep_heap
from catabot.bus.identity import add_roster_args
from catabot.bus.keys import Keys
from catabot.bus.members import NameTaken
from catabot.bus.session import (
    add_connection_args,
    connection_from_args,
    open_session,
)
from catabot.bus.settings import Schedule
from catabot.config import live
from catabot.config.load import digest, load_scenario
from catabot.config.notes import late_settings
from catabot.config.scenario import Scenario, participants
from catabot.errors import CataBotError
from catabot.run.advice import advise
from catabot.run.answer import OneLineParser
from catabot.run.service import quiet_gc
from catabot.run.settings_desk import SettingsDesk
from catabot.run.usage import memory_mb
from catabot.run.world_info import WorldInfoDesk

log = logging.getLogger("catabot.bus.conductor")


def clock_spec(scenario: Scenario, start_timeout_s: float | None = None) -> ClockSpec:
    """The clock of a run; `start_timeout_s` (`--start-timeout`) replaces the scenario's."""
    c = scenario.clock
    return ClockSpec(
        dt_ns=scenario.dt_ns,
        ticks=scenario.ticks,
        participants=tuple(participants(scenario)),
        deadline_s=c.deadline_s,
        start_timeout_s=start_timeout_s or c.start_timeout_s,
        policy=Policy(c.policy),
        realtime_factor=c.realtime_factor,
        window_ticks=c.window_ticks,
        digest=digest(scenario),
    )


_EMIT = threading.Lock()  # the heartbeat thread and the tick loop share stdout
HEARTBEAT_S = 0.5


def _tell_late_settings(scenario: Scenario) -> None:
    """Advice on timeline entries after the run's last tick (taken, never applied)."""
    for text in late_settings(scenario):
        advise(log, text)


def emit(kind: str, **fields: object) -> bool:
    """One JSON line on stdout; False once nobody reads it (the launcher is gone)."""
    try:
        with _EMIT:
            sys.stdout.write(json.dumps({"kind": kind, **fields}) + "\n")
            sys.stdout.flush()
    except (BrokenPipeError, ValueError):  # ValueError: stdout already closed
        return False
    return True


def heartbeat(stop: threading.Event) -> None:
    """`alive` every half second: the launcher takes silence for a hung conductor (at a
    terminal, `catabot service conductor` by hand, nobody reads it)."""
    if sys.stdout.isatty():
        return
    while not stop.wait(HEARTBEAT_S):
        emit("alive")


def main(argv: list[str] | None = None) -> int:
    parser = OneLineParser(prog="catabot service conductor")
    parser.add_argument("--scenario", help="scenario file (default: the bundled default)")
    add_connection_args(parser)
    add_roster_args(parser)
    parser.add_argument(
        "--start-timeout",
        type=_seconds,
        metavar="S",
        help="how long to wait for every participant (default: clock.start_timeout_s)",
    )
    parser.add_argument(
        "--linger",
        type=_seconds,
        default=0.0,
        metavar="S",
        help="after the end, wait up to S s for every participant to leave (in containers)",
    )
    args = parser.parse_args(argv)
    stop = threading.Event()  # the heartbeat, from before the session (a login takes a while)
    threading.Thread(target=heartbeat, args=(stop,), name="heartbeat", daemon=True).start()
    single_thread_blas()
    keep_heap()
    logging.basicConfig(level=logging.INFO, format="%(asctime)s %(name)s %(levelname)s %(message)s")
    try:
        scenario = load_scenario(args.scenario)
        session = open_session(connection_from_args(args))
    except CataBotError as exc:
        emit("result", ticks_done=0, wall_s=0.0, error=str(exc), dropped=[], reason="fault")
        return 2
    keys = Keys(scenario.name)
    schedule = Schedule(live.timeline(scenario), ticks=scenario.ticks, grace_s=live.apply_grace_s)
    _tell_late_settings(scenario)
    spec = clock_spec(scenario, args.start_timeout)
    try:
        conductor = Conductor(session, keys, spec, roster=args.roster, settings=schedule)
    except NameTaken as exc:  # a second conductor of this world: said on stderr too
        log.critical("%s", exc)
        emit("result", ticks_done=0, wall_s=0.0, error=str(exc), dropped=[], reason="fault")
        session.close()
        return 2
    info = WorldInfoDesk(session, scenario, args.roster, schedule)  # for stacks: catabot.client
    desk = SettingsDesk(session, keys, scenario, schedule, planned=info.behaviours)
    quiet_gc()
    for sig in (signal.SIGINT, signal.SIGTERM):
        signal.signal(sig, lambda *_: conductor.stop("interrupted"))
    signal.signal(signal.SIGUSR1, lambda *_: conductor.stop("fault"))  # a process of it died
    emit("ready")  # from now on a stop ends the run cleanly (the launcher holds one till then)

    def progress(p: Progress) -> None:
        # Without its launcher the run has no one to report to: end it cleanly (services
        # flush and exit) rather than tick on as orphans.
        if not emit("progress", **asdict(p)):
            conductor.stop(LAUNCHER_GONE)

    result = conductor.run(progress)
    desk.close()
    info.close()
    stop.set()
    rejected = conductor.rejections.totals + desk.rejections.totals
    settings = [live.entry(c, scenario.dt_ns) for c in schedule.asked()]
    emit("result", **asdict(result), rejected=dict(rejected), settings=settings,
         **memory_mb())  # fmt: skip
    if result.error:
        log.error("run ended by a fault: %s", result.error)
    conductor.close()
    _linger(session, keys, args.linger)
    session.close()
    return 1 if result.error else (130 if result.reason == "interrupted" else 0)


def _seconds(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        value = -1.0
    if not 0 < value < 1e6:
        raise argparse.ArgumentTypeError(f"{text!r}: seconds, more than 0 and less than 1e6")
    return value


def _linger(session: zenoh.Session, keys: Keys, linger_s: float) -> None:
    """Wait until no participant's liveliness token is left (a service drops it once its
    files are closed), at most `linger_s`. In containers the conductor's exit is the run's
    end (`docker compose run conductor` returns, then `down` stops the rest): without this,
    the recorder could be stopped while it still writes the last ticks."""
    limit = time.monotonic() + linger_s
    while time.monotonic() < limit:
        left = [r for r in session.liveliness().get(keys.lives(), timeout=1.0) if r.ok]
        if not left:
            return
        time.sleep(0.2)
    if linger_s:
        log.warning("participants still on the bus %g s after the end", linger_s)


def exit_now(code: int) -> NoReturn:
    """Leave without the interpreter's shutdown. Zenoh's threads may still call into Python
    then (a token gone, a late sample), and CPython ends such a thread with a forced unwind
    through Zenoh's Rust frames, which aborts the process ("FATAL: exception not rethrown",
    exit 134: seen twice in sixteen distributed runs, after the result was printed)."""
    logging.shutdown()
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(code)


if __name__ == "__main__":
    exit_now(main())
