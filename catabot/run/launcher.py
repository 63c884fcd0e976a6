"""`catabot run`: the conductor and every service as separate OS processes.

The launcher owns no simulation state: it checks the scenario, makes the run folder,
starts the processes with their logs in `log/`, draws progress from the conductor's
JSON lines, and turns the end of the run into a summary and an exit code.
"""

from __future__ import annotations

import contextlib
import json
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Iterator
from dataclasses import dataclass
from datetime import datetime
from pathlib import Path

from catabot.bus.clock import CONDUCTOR
from catabot.bus.identity import Roster, new_zid
from catabot.bus.scheduling import requested_policy
from catabot.bus.session import free_port
from catabot.config.load import load_scenario, parse_scenario
from catabot.config.scenario import Scenario
from catabot.errors import CataBotError
from catabot.run.progress import ProgressBar
from catabot.run.summary import summarise
from catabot.world.world import World

SERVICE_MODULES = {
    "physics": "services.physics",
    "sensors": "services.sensors",
    "traffic": "services.traffic",
    "recorder": "services.recorder",
}


class LaunchError(CataBotError, RuntimeError):
    """The run could not start (bad scenario, missing model, unknown service)."""


@dataclass(frozen=True)
class RunOptions:
    scenario: str | None = None
    duration_s: float | None = None
    realtime: float | None = None
    out: Path = Path("runs")
    connect: tuple[str, ...] = ()
    listen: str | None = None
    quiet: bool = False


def prepare(opts: RunOptions) -> World:
    """Everything that can be refused is refused here, before any process starts: the world
    is resolved once (poses, traffic, models, terrain), as every service will resolve it."""
    requested_policy()  # a bad CATABOT_SCHED would stop every service
    scenario = load_scenario(opts.scenario)
    data = scenario.model_dump()
    if opts.duration_s is not None:
        data["duration_s"] = opts.duration_s
    if opts.realtime is not None:
        data["clock"]["realtime_factor"] = opts.realtime
    world = World.resolve(parse_scenario(data, source="command line"))
    for name in world.services:
        if name not in SERVICE_MODULES:
            raise LaunchError(f"scenario needs service {name!r}, which this version does not have")
    return world


def make_run_dir(out: Path, scenario: Scenario) -> Path:
    stamp = datetime.now().strftime("%Y%m%d-%H%M%S")
    base = out / f"{scenario.name}-{stamp}"
    run_dir, n = base, 1
    while run_dir.exists():
        n += 1
        run_dir = Path(f"{base}-{n}")
    (run_dir / "log").mkdir(parents=True)
    (run_dir / "scenario.json").write_text(scenario.model_dump_json(indent=2) + "\n")
    return run_dir


def _endpoints(opts: RunOptions) -> tuple[list[str], list[str]]:
    """Flags for the conductor and for the services: embedded peer mesh, or a router."""
    if opts.connect:
        flags = [f for ep in opts.connect for f in ("--connect", ep)] + ["--mode", "client"]
        return flags, flags
    listen = opts.listen or f"tcp/127.0.0.1:{free_port()}"
    return ["--listen", listen], ["--connect", listen]


def _identity(roster: Roster, name: str) -> list[str]:
    """A process's own session id and everyone's (only these sessions may drive the clock
    and produce lockstep data: catabot/bus/identity.py)."""
    return ["--zid", str(roster.zid(name)), "--roster", str(roster)]


def _spawn(args: list[str], log_file: Path, *, stdout_pipe: bool = False) -> subprocess.Popen[str]:
    log = log_file.open("w")
    return subprocess.Popen(
        [sys.executable, "-m", *args],
        stdout=subprocess.PIPE if stdout_pipe else log,
        stderr=log,
        text=True,
        start_new_session=True,  # Ctrl-C reaches the launcher only; it ends the run cleanly
    )


def run(opts: RunOptions) -> int:
    try:
        world = prepare(opts)
    except CataBotError as exc:
        print(f"catabot run: {exc}", file=sys.stderr)
        return 2
    scenario = world.scenario
    stops = Stops()
    with stops.installed():  # from before the first process starts
        run_dir = make_run_dir(opts.out, scenario)
        cond_flags, svc_flags = _endpoints(opts)
        print(
            f"run folder: {run_dir}\nzenoh: clients connect to {svc_flags[1]} (world "
            f"{scenario.name!r}, keys catabot/{scenario.name}/...)",
            flush=True,
        )
        scen = str(run_dir / "scenario.json")
        roster = Roster({name: new_zid() for name in (CONDUCTOR, *world.services)})
        stops.conductor = conductor = _spawn(
            ["catabot.run.conduct", "--scenario", scen, *cond_flags, *_identity(roster, CONDUCTOR)],
            run_dir / "log" / "conductor.log",
            stdout_pipe=True,
        )
        common = ["--scenario", scen, "--run-dir", str(run_dir), *svc_flags]
        services = {
            name: _spawn(
                [SERVICE_MODULES[name], *common, *_identity(roster, name)],
                run_dir / "log" / f"{name}.log",
            )
            for name in world.services
        }
        return Supervisor(scenario, run_dir, conductor, services, stops, quiet=opts.quiet).wait()


class Stops:
    """Ctrl-C, SIGTERM and SIGHUP all end the run cleanly through the conductor (a launcher
    killed by its shell or a process manager must leave no orphans ticking). A request is
    held until the conductor says it is ready: a signal before its handlers are set would
    kill it outright."""

    def __init__(self) -> None:
        self.requested = False
        self.ready = threading.Event()
        self.conductor: subprocess.Popen[str] | None = None

    @contextlib.contextmanager
    def installed(self) -> Iterator[None]:
        signals = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)
        previous = {sig: signal.signal(sig, self._on_signal) for sig in signals}
        try:
            yield
        finally:
            for sig, handler in previous.items():
                signal.signal(sig, handler)

    def _on_signal(self, *_: object) -> None:
        self.requested = True
        self.forward()

    def forward(self) -> None:
        """Pass a held request to the conductor once it takes signals."""
        if self.requested and self.ready.is_set() and self.conductor is not None:
            self.conductor.send_signal(signal.SIGINT)


class Supervisor:
    """Watches the processes of one run until all have ended."""

    def __init__(
        self,
        scenario: Scenario,
        run_dir: Path,
        conductor: subprocess.Popen[str],
        services: dict[str, subprocess.Popen[str]],
        stops: Stops,
        *,
        quiet: bool,
    ) -> None:
        self.scenario, self.run_dir = scenario, run_dir
        self.conductor, self.services, self.stops = conductor, services, stops
        self.bar = ProgressBar(scenario.duration_ns, enabled=not quiet)
        self.result: dict[str, object] = {}
        self.stopped: set[str] = set()  # services the launcher had to stop

    def wait(self) -> int:
        self._read_conductor()
        self._reap_services(timeout_s=self._reap_timeout())
        return self._summary()

    def _read_conductor(self) -> None:
        """Follow the conductor's lines; stop it if a service dies before it notices."""
        reader = threading.Thread(target=self._follow, daemon=True)
        reader.start()
        stopped = False
        while reader.is_alive():
            reader.join(timeout=0.1)
            died = [n for n, p in self.services.items() if p.poll() not in (None, 0)]
            if died and not stopped and self.conductor.poll() is None:
                self.conductor.send_signal(signal.SIGTERM)
                stopped = True
        self.conductor.wait()
        self.bar.close()

    def _follow(self) -> None:
        assert self.conductor.stdout is not None
        for line in self.conductor.stdout:
            try:
                event = json.loads(line)
            except json.JSONDecodeError:
                continue
            if event.get("kind") == "ready":
                self.stops.ready.set()
                self.stops.forward()
            elif event.get("kind") == "progress":
                self.bar.update(event)
            elif event.get("kind") == "result":
                self.result = event

    def _reap_timeout(self) -> float:
        """Services end by themselves after the conductor's End (15 s allows their last
        flush); a service still starting when an interrupted run ended never joined, so it
        never hears the End: it is stopped at once, and not blamed (`self.stopped`)."""
        joined = int(self.result.get("ticks_done", 0)) > 0  # type: ignore[call-overload]
        return 15.0 if joined or self.result.get("reason") != "interrupted" else 1.0

    def _reap_services(self, *, timeout_s: float) -> None:
        limit = time.monotonic() + timeout_s
        for name, proc in self.services.items():
            try:
                proc.wait(timeout=max(limit - time.monotonic(), 0.1))
            except subprocess.TimeoutExpired:
                self.stopped.add(name)
                proc.terminate()
                try:
                    proc.wait(timeout=3)
                except subprocess.TimeoutExpired:
                    proc.kill()
                    proc.wait()

    def _summary(self) -> int:
        return summarise(
            self.scenario,
            self.run_dir,
            self.result,
            self.conductor.returncode,
            {n: p.returncode for n, p in self.services.items()},
            stopped=self.stopped,
        )
