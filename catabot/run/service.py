"""What every service program shares: flags, logging, the session, the exit code.

A service is `def build(ctx) -> (participant, step, on_end)`; this module opens Zenoh,
runs the lockstep loop, and turns faults into one clear log line and a non-zero exit.
"""

from __future__ import annotations

import argparse
import cProfile
import gc
import logging
import os
import signal
import sys
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Protocol

import zenoh

from catabot.bus.blas import single_thread_blas
from catabot.bus.clock import ClockError, Stream, who_never_joined
from catabot.bus.heap import keep_heap
from catabot.bus.identity import Roster, add_roster_args
from catabot.bus.inbox import Inbox, Inputs
from catabot.bus.keys import Keys
from catabot.bus.messages import End, Tick
from catabot.bus.participant import LOST, EndFn, Participant, StepFn
from catabot.bus.rejections import Rejections
from catabot.bus.scheduling import batch_scheduling
from catabot.bus.session import (
    add_connection_args,
    connection_from_args,
    open_session,
)
from catabot.bus.settings import changes_of
from catabot.config import live
from catabot.config.load import load_scenario
from catabot.config.scenario import Scenario, services, shard_count
from catabot.config.sensors import shard_names
from catabot.errors import CataBotError
from catabot.run.answer import OneLineParser
from catabot.run.usage import write_usage
from catabot.world.world import World

EXIT_CLOCK = 3  # the lockstep clock was lost (the conductor gone, a hung peer)
FAULT_SENT_S = 0.1
log = logging.getLogger("catabot.run.service")


@dataclass
class ServiceContext:
    """What a service is built from: the resolved world, its session and run folder."""

    name: str
    world: World
    session: zenoh.Session
    run_dir: Path
    roster: Roster = field(default_factory=Roster)

    @property
    def scenario(self) -> Scenario:
        return self.world.scenario

    @property
    def keys(self) -> Keys:
        return self.world.keys

    @property
    def peers(self) -> list[str]:
        return self.world.participants

    def participant(self, inputs: Sequence[Stream]) -> Participant:
        """This service in the lockstep: its inputs, peers, roster and the clock's limits."""
        return Participant(
            self.session,
            self.keys,
            self.name,
            inputs=inputs,
            peers=self.peers,
            roster=self.roster,
            limits=self.world.clock_limits,
        )


class Runner(Protocol):
    """What runs a service to the end of the run: a lockstep `Participant`, or an observer
    that steps on what it receives (services/ros)."""

    rejections: Rejections  # what it refused, written to log/<name>.rejected.json

    def run(self, step: StepFn, on_end: EndFn | None = None) -> End: ...


Built = tuple[Runner, StepFn, EndFn | None]
BuildFn = Callable[[ServiceContext], Built]


def service_parser(name: str) -> argparse.ArgumentParser:
    parser = OneLineParser(prog=f"catabot service {name}")
    parser.add_argument("--scenario", help="scenario file (default: the bundled default)")
    parser.add_argument(
        "--run-dir", help="run folder for outputs, the same for every service of a run "
        "(default: runs/<the scenario's name>, as `catabot deploy compose` lays it out)",
    )  # fmt: skip
    add_connection_args(parser)
    add_roster_args(parser)
    return parser


def setup_logging() -> None:
    logging.basicConfig(
        level=logging.INFO,
        stream=sys.stderr,
        format="%(asctime)s %(name)s %(levelname)s %(message)s",
    )


def _profiled(name: str, run_dir: Path, run: Callable[[], End]) -> End:
    """`CATABOT_PROFILE=1`: cProfile the stepping loop into `log/<service>.prof` (open with
    `python -m pstats`); sampling profilers miss much of a process that mostly waits.
    `CATABOT_PROFILE=cpu` times the main thread's CPU instead of the wall clock, so waits
    and preemption by the other processes drop out of the figures."""
    if not os.environ.get("CATABOT_PROFILE"):
        return run()
    cpu = os.environ["CATABOT_PROFILE"] == "cpu"  # main thread's CPU time, not wall time
    profile = cProfile.Profile(time.thread_time) if cpu else cProfile.Profile()
    try:
        return profile.runcall(run)
    finally:
        (run_dir / "log").mkdir(parents=True, exist_ok=True)
        profile.dump_stats(run_dir / "log" / f"{name}.prof")


def quiet_gc() -> None:
    """Freeze what start-up built and collect cycles 100x less often: a tick's garbage is
    freed by reference counting, yet every 700 allocations the collector walked the young
    objects (3 % of the physics process's CPU with one vessel)."""
    gc.collect()
    gc.freeze()
    gc.set_threshold(70_000, 10, 10)


class ShardError(CataBotError, ValueError):
    """A `--shard` that does not match the scenario's split."""


def parse_shard(text: str) -> tuple[int, int]:
    i, sep, n = text.partition("/")
    if not (sep and i.isdigit() and n.isdigit() and 0 <= int(i) < int(n)):
        raise argparse.ArgumentTypeError(f"{text!r}: use I/N with 0 <= I < N, e.g. 0/2")
    return int(i), int(n)


WHY_NOT = {"sensors": "no vessel has sensors", "traffic": "traffic.count is 0"}


class NotInScenario(CataBotError, ValueError):
    """A service started for a scenario that does not run it."""


def own_name(service: str, world: World, shard: tuple[int, int] | None) -> str:
    """This process's participant name: the service's own, or its shard's (`sensors.1`).
    NotInScenario for sensors or traffic where the scenario has none (traffic without boats
    crashed with a KeyError; sensors without sensors joined and stepped nothing). The ROS
    gateway may run on any scenario, with the default ROS settings."""
    needed = services(world.scenario)
    if service in WHY_NOT and not any(n.partition(".")[0] == service for n in needed):
        raise NotInScenario(f"scenario {world.scenario.name!r} does not run {service} "
                            f"({WHY_NOT[service]}); it runs {', '.join(needed)}")  # fmt: skip
    n = shard_count(world.scenario, service)
    if shard is None and n == 1:
        return service
    split = (f"the scenario runs {service} as one process ({service}.shards 1)" if n == 1 else
             f"the scenario splits {service} over {n} processes ({service}.shards)")  # fmt: skip
    if shard is None:
        raise ShardError(f"{split}: start each with --shard I/{n}")
    if shard[1] != n:
        raise ShardError(f"--shard {shard[0]}/{shard[1]}: {split}")
    return shard_names(service, n)[shard[0]]


def run_service(
    name: str,
    build: BuildFn,
    argv: list[str] | None = None,
    *,
    timestamping: bool = False,
    shardable: bool = False,
) -> int:
    """Run one stepping service to the end of the run; returns the process exit code.

    A fault of the service's own is logged as CRITICAL (what `catabot run` reports as the
    run's cause); a fault of the clock (the conductor gone, the run ended by a fault
    elsewhere) as ERROR: it is a consequence, not a cause. `timestamping`: the session stamps
    samples (Zenoh's advanced publishers need it). `shardable`: it takes `--shard I/N` and
    runs as that shard (`sensors.shards`)."""
    parser = service_parser(name)
    if shardable:
        what = "run shard I of the N the scenario splits this service into"
        parser.add_argument("--shard", type=parse_shard, metavar="I/N", help=what)
    args = parser.parse_args(argv)
    setup_logging()
    single_thread_blas()  # idle BLAS threads spin on the cores other services need
    keep_heap()  # reuse freed arrays instead of faulting fresh pages in every tick
    signal.signal(signal.SIGTERM, _stopped)
    try:
        batch_scheduling()  # before Zenoh starts its threads, so that they inherit it
        world = World.resolve(load_scenario(args.scenario))  # the same in every process
        name = own_name(name, world, getattr(args, "shard", None))
        session = open_session(replace(connection_from_args(args), timestamping=timestamping))
    except CataBotError as exc:
        log.critical("%s", exc)
        return 2
    try:
        run_dir = Path(args.run_dir or Path("runs") / world.scenario.name)  # not the cwd
        return _serve(ServiceContext(name, world, session, run_dir, args.roster), build)
    finally:
        session.close()


class Terminated(SystemExit):
    """SIGTERM: exit 143, as before, once the conductor has been told why (it had named a
    stopped service as one that left "without a word")."""


def _stopped(*_: object) -> None:
    log.warning("stopped by SIGTERM (exit 143)")
    raise Terminated(143)


def with_switches(ctx: ServiceContext, runner: Runner, step: StepFn) -> StepFn:
    """`step`, first telling the inbox of sensors switched off or on at this tick (`catabot
    set sensor.<vessel>.<sensor>.enabled`), so a consumer of a sensor that is off does not
    wait for its samples; every service gets this, whatever it reads."""
    inbox = getattr(runner, "inbox", None)
    specs = live.keys_of(ctx.scenario).items()
    streams = {k: ctx.keys.sensor(s.owner, s.name) for k, s in specs if s.kind == "enabled"}
    if not isinstance(inbox, Inbox) or not set(streams.values()) & set(inbox.streams):
        return step

    def switched(tick: Tick, inputs: Inputs) -> None:
        for change in changes_of(tick.settings):
            key = streams.get(change.key)
            if key is not None and key in inbox.streams:
                inbox.switch(key, tick.tick, on=bool(change.decoded))
        step(tick, inputs)

    return switched


def _serve(ctx: ServiceContext, build: BuildFn) -> int:
    participant: Runner | None = None
    try:
        participant, step, on_end = build(ctx)
        step = with_switches(ctx, participant, step)
        quiet_gc()
        cpu_start = time.process_time()
        end = _profiled(ctx.name, ctx.run_dir, lambda: participant.run(step, on_end))
        write_usage(ctx.name, ctx.run_dir, time.process_time() - cpu_start)
        participant.rejections.write(ctx.run_dir / "log" / f"{ctx.name}.rejected.json")
    except Terminated:
        _tell_sigterm(participant)
        raise
    except ClockError as exc:
        log.error("%s", exc)
        return EXIT_CLOCK
    except CataBotError as exc:
        return _failed(participant, 2, str(exc))
    except OSError as exc:
        return _failed(participant, 1, f"{exc.filename or 'I/O'}: {exc.strerror or exc}")
    except Exception as exc:  # a bug: its traceback in the log, named as the cause
        if _from_sigterm(exc):  # the signal met a compiled (numba) call: a SystemError
            _tell_sigterm(participant)
            raise Terminated(143) from None
        return _failed(participant, 1, f"crashed: {type(exc).__name__}: {exc}", trace=True)
    if end.reason == LOST:  # its files are closed whole, up to the last tick it stepped
        log.error("%s (its files end at tick %d)", end.error, end.tick)
        return EXIT_CLOCK
    if getattr(participant, "next_tick", 1) == 0 and ctx.name in who_never_joined(end.error):
        log.error("%s: the conductor never saw this process join (%s): another world or "
                  "router, or a login (secure profile) that may not declare its token?",
                  ctx.name, end.error)  # fmt: skip
        return 1
    log.info("%s: run ended at tick %d (%s) %s", ctx.name, end.tick, end.reason, end.error)
    return 0


def _tell_sigterm(participant: Runner | None) -> None:
    if isinstance(participant, Participant):
        participant.report_fault("stopped by SIGTERM (exit 143)")
        time.sleep(FAULT_SENT_S)  # the put leaves before the session closes


def _from_sigterm(exc: BaseException | None) -> bool:
    """Whether `exc` wraps the SIGTERM handler's Terminated: raised as a numba-compiled call
    returned, it came out as "SystemError: CPUDispatcher(...) returned a result with an
    exception set", and the run named the service as crashed (a CI rehearsal)."""
    seen = 0
    while exc is not None and seen < 16:
        if isinstance(exc, Terminated):
            return True
        exc, seen = exc.__cause__ or exc.__context__, seen + 1
    return False


def _failed(runner: Runner | None, code: int, why: str, *, trace: bool = False) -> int:
    """A fault of this service's own: CRITICAL in its log (the cause `catabot run` quotes),
    and told to the conductor, whose error names it on every host of a split run."""
    log.critical("%s", why, exc_info=trace)
    if isinstance(runner, Participant):
        runner.report_fault(why)
        time.sleep(FAULT_SENT_S)  # the put leaves before the session closes
    return code
