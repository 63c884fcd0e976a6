"""`catabot run`: the conductor and every service as separate OS processes.

The launcher owns no simulation state: it checks the scenario, makes the run folder,
starts the processes with their logs in `log/`, draws progress from the conductor's
JSON lines, and turns the end of the run into a summary and an exit code.
"""

from __future__ import annotations

import math
import sys
from dataclasses import dataclass
from datetime import datetime
from pathlib import Path

from catabot.bus.clock import CONDUCTOR
from catabot.bus.identity import Roster, new_zid
from catabot.bus.scheduling import requested_policy
from catabot.bus.session import check_listen, check_router, free_port
from catabot.config.base import ScenarioError
from catabot.config.load import (
    load_scenario,
    parse_scenario,
    scenario_data,
    scenario_json,
    with_sets,
)
from catabot.config.scenario import Scenario
from catabot.config.sensors import service_of
from catabot.errors import CataBotError
from catabot.run import programs
from catabot.run.announce import announce
from catabot.run.child import Child
from catabot.run.companions import Viewer, after_run, start_viewer
from catabot.run.progress import PlanningProgress, ProgressBar
from catabot.run.provenance import write_started
from catabot.run.summary import summarise
from catabot.run.supervisor import Stops, Supervisor
from catabot.world.mounts import check_mounts
from catabot.world.world import World

SERVICE_MODULES = {
    "physics": "services.physics",
    "sensors": "services.sensors",
    "traffic": "services.traffic",
    "recorder": "services.recorder",
    "ros": "services.ros",
}


class LaunchError(CataBotError, RuntimeError):
    """The run could not start (bad scenario, missing model, unknown service)."""


@dataclass(frozen=True)
class RunOptions:
    scenario: str | None = None
    duration_s: float | None = None
    seed: int | None = None
    realtime: float | None = None
    out: Path = Path("runs")
    connect: tuple[str, ...] = ()
    listen: str | None = None
    quiet: bool = False
    zenoh_configs: Path | None = None  # a folder of <process>.json5 (the secure profile)
    view: str | None = None  # one of VIEW_MODES: the live rerun viewer beside the run
    sets: tuple[str, ...] = ()  # --set FIELD=VALUE, in order (catabot/config/overrides.py)
    run_dir: Path | None = None  # --run-dir: this folder, not <out>/<name>-<time>


def prepare(opts: RunOptions) -> World:
    """Everything that can be refused is refused here, before any process starts: the world
    is resolved once (poses, traffic, models, terrain), as every service will resolve it."""
    requested_policy()  # a bad CATABOT_SCHED would stop every service
    for endpoint in opts.connect:
        check_router(endpoint)
    if opts.listen and not opts.connect:  # the embedded mesh: the conductor listens there
        check_listen(opts.listen)
    scenario, source = _with_sets(opts), opts.scenario or "default"
    data, flags = scenario.model_dump(), [f"--set {item}" for item in opts.sets]
    if opts.duration_s is not None:
        data["duration_s"] = opts.duration_s
        flags.append(f"--duration {opts.duration_s:g}")
    if opts.seed is not None:
        data["seed"] = opts.seed
        flags.append(f"--seed {opts.seed}")
    if opts.realtime is not None:  # 0 or inf: as fast as possible, a file's pace undone
        if not opts.realtime >= 0.0:
            raise ScenarioError(f"--realtime {opts.realtime:g}: a pace is 0 or more (1: the wall "
                                "clock, 0: as fast as possible)")  # fmt: skip
        fast = opts.realtime == 0.0 or opts.realtime == math.inf
        data["clock"]["realtime_factor"] = None if fast else opts.realtime
        flags.append(f"--realtime {opts.realtime:g}")
    changed = f"{source} with {' '.join(flags)}" if flags else source  # the file, the flags
    parsed = parse_scenario(data, source=changed)
    try:
        world = World.resolve(parsed, progress=PlanningProgress())
    except ScenarioError as exc:  # which file, as the parser's own errors say
        raise ScenarioError(f"scenario {source}: {exc}") from None
    _ = world.shapes  # every mesh file read now: a broken one is refused before any start
    check_mounts(world)  # no camera, LiDAR or radar inside its own hull
    for name in world.services:
        if service_of(name, world.services)[0] not in SERVICE_MODULES:
            raise LaunchError(f"scenario needs service {name!r}, which this version does not have")
    programs.programs(world.scenario, opts.scenario)  # each controller's program is a file
    _check_run_dir(opts.run_dir)
    _check_logins(opts, world)
    return world


def _with_sets(opts: RunOptions) -> Scenario:
    """The scenario, with `--set`'s changes made to the file's own data (overrides.py)."""
    if not opts.sets:
        return load_scenario(opts.scenario)
    data, file = scenario_data(opts.scenario)
    flags = with_sets(data, list(opts.sets), source=str(file), flagged=_flagged(opts))
    return parse_scenario(data, source=f"{opts.scenario or 'default'} with {' '.join(flags)}")


def _check_run_dir(folder: Path | None) -> None:
    """`--run-dir`: a new or empty folder (a run folder holds one run's files)."""
    if folder is None or not folder.exists():
        return
    if not folder.is_dir():
        raise LaunchError(f"--run-dir {folder}: a file, not a folder")
    if any(folder.iterdir()):
        raise LaunchError(f"--run-dir {folder}: not empty; a run folder holds one run")


def _flagged(opts: RunOptions) -> dict[str, str]:
    """The fields a flag of their own gives (a `--set` of them as well is refused)."""
    given = {"duration_s": opts.duration_s, "seed": opts.seed,
             "clock.realtime_factor": opts.realtime}  # fmt: skip
    names = {"duration_s": "--duration", "seed": "--seed", "clock.realtime_factor": "--realtime"}
    return {field: names[field] for field, value in given.items() if value is not None}


def _check_logins(opts: RunOptions, world: World) -> None:
    """In the secure profile every process needs its own login file."""
    if opts.zenoh_configs is None:
        return
    names = [CONDUCTOR, *world.services, *(["viewer"] if opts.view else [])]
    names += [p.participant for p in programs.programs(world.scenario, opts.scenario)]
    missing = [n for n in names if not (opts.zenoh_configs / f"{n}.json5").is_file()]
    if missing:
        raise LaunchError(
            f"secure profile {opts.zenoh_configs} has no login for {', '.join(missing)} (the ROS "
            "gateway is not in the secure profile; a controller's program needs a client login: "
            "catabot secure init --client NAME; shards need --sensor-shards/--traffic-shards N; "
            "otherwise make it with catabot secure init)"
        )


def make_run_dir(out: Path, scenario: Scenario, *, exact: Path | None = None) -> Path:
    """`<name>-<time>`, or `-2`, `-3`, ... after it: the folder is taken by making it, so
    runs started in one second beside each other (`xargs -P`) each get their own (a check
    then a make had let two race, and the loser exit 2 as if its scenario were bad).
    `exact` (`--run-dir`): that folder, new or empty (a sweep's script names its runs)."""
    if exact is not None:
        exact.mkdir(parents=True, exist_ok=True)
        return _filled(exact, scenario)
    stamp = datetime.now().strftime("%Y%m%d-%H%M%S")
    base = out / f"{scenario.name}-{stamp}"
    out.mkdir(parents=True, exist_ok=True)
    run_dir, n = base, 1
    while True:
        try:
            run_dir.mkdir()
            break
        except FileExistsError:
            n += 1
            run_dir = Path(f"{base}-{n}")
    return _filled(run_dir, scenario)


def _filled(run_dir: Path, scenario: Scenario) -> Path:
    (run_dir / "log").mkdir()
    (run_dir / "scenario.json").write_text(scenario_json(scenario))
    write_started(run_dir, scenario)
    return run_dir


def _endpoints(opts: RunOptions) -> tuple[list[str], list[str]]:
    """Flags for the conductor and for the services: embedded peer mesh, or a router."""
    if opts.connect:
        flags = [f for ep in opts.connect for f in ("--connect", ep)] + ["--mode", "client"]
        return flags, flags
    listen = opts.listen or f"tcp/127.0.0.1:{free_port()}"
    return ["--listen", listen], ["--connect", listen]


def _identity(roster: Roster, name: str, configs: Path | None) -> list[str]:
    """A process's own session id and everyone's (only these sessions may drive the clock
    and produce lockstep data: catabot/bus/identity.py), and its Zenoh config file in the
    secure profile (its own credentials: catabot/run/secure.py)."""
    return ["--zid", str(roster.zid(name)), "--roster", str(roster), *_login(name, configs)]


def _login(name: str, configs: Path | None) -> list[str]:
    return ["--zenoh-config", str(configs / f"{name}.json5")] if configs else []


def run(opts: RunOptions) -> int:
    try:
        world = prepare(opts)
    except CataBotError as exc:
        print(f"catabot run: {exc}", file=sys.stderr)
        return 2
    scenario = world.scenario
    stops = Stops()
    with stops.installed():  # from before the first process starts
        try:
            run_dir = make_run_dir(opts.out, scenario, exact=opts.run_dir)
        except OSError as exc:
            where = opts.run_dir or f"a run folder in {opts.out}"
            print(f"catabot run: cannot make {where}: {exc.strerror}", file=sys.stderr)
            return 2
        cond_flags, svc_flags = _endpoints(opts)
        print(f"run folder: {run_dir}", flush=True)
        supervisor, viewer = _start(world, run_dir, opts, stops, (cond_flags, svc_flags))
        listener = None if opts.connect else supervisor.conductor.proc  # it listens there
        announce(world, scenario_file=opts.scenario, endpoint=svc_flags[1], listener=listener)
        code = _watch(scenario, run_dir, supervisor, quiet=opts.quiet)
    _close_viewer(viewer)
    return code


def _start(
    world: World,
    run_dir: Path,
    opts: RunOptions,
    stops: Stops,
    flags: tuple[list[str], list[str]],
) -> tuple[Supervisor, Viewer | None]:
    """The conductor, the viewer (it sees the run from tick 0), every service, then every
    controller's program, each a process with its own session id."""
    scen = str(run_dir / "scenario.json")
    stacks = programs.programs(world.scenario, opts.scenario)
    names = (CONDUCTOR, *world.services, *(p.participant for p in stacks))
    roster = Roster({name: new_zid() for name in names})

    def child(name: str, module: str, extra: list[str], *, stdout: bool = False) -> Child:
        identity = _identity(roster, name, opts.zenoh_configs)
        args = [module, "--scenario", scen, *extra, *identity]
        return Child(name, args, run_dir / "log" / f"{name}.log", stdout=stdout)

    conductor = child(CONDUCTOR, "catabot.run.conduct", flags[0], stdout=True)
    stops.conductor = conductor.proc
    viewer = _viewer(opts, run_dir, [*flags[1], *_login("viewer", opts.zenoh_configs)])
    services = {}
    for name in world.services:
        program, shard = service_of(name, world.services)  # a shard: --shard I/N
        extra = ["--run-dir", str(run_dir), *flags[1], *shard]
        services[name] = child(name, SERVICE_MODULES[program], extra)
    for stack in stacks:
        name = stack.participant
        own = [*flags[1], "--zid", str(roster.zid(name)), *_login(name, opts.zenoh_configs)]
        services[name] = Child(
            name,
            programs.command(stack, world.scenario.name, own),
            run_dir / "log" / f"{name}.log",
            stdout=False,
            program=True,
            env=programs.environment(run_dir),
        )
    goes_on = world.scenario.clock.policy == "drop"
    return Supervisor(conductor, services, stops, goes_on=goes_on), viewer


def _viewer(opts: RunOptions, run_dir: Path, svc_flags: list[str]) -> Viewer | None:
    """The live viewer (`--view`), subscribed before any service starts."""
    if opts.view is None:
        return None
    viewer = start_viewer(opts.view, run_dir, svc_flags, hold=sys.stdin.isatty())
    if not viewer.wait_ready():
        print(f"catabot run: the viewer did not start: {viewer.why()} (for a run: --view "
              "web, or --set recording.rerun=true for run.rrd)", file=sys.stderr)  # fmt: skip
    elif viewer.url:
        print(f"rerun web viewer: {viewer.url}", flush=True)
    return viewer


def _close_viewer(viewer: Viewer | None) -> None:
    """The native viewer's feeder ends with the run; the web viewer is served until Ctrl-C
    when someone is at the terminal (a script's run just ends)."""
    if viewer is None:
        return
    if viewer.url and sys.stdin.isatty():
        viewer.hold()
    else:
        viewer.stop(wait_s=15)  # it ends by itself once the run's End and metrics are in


def _watch(scenario: Scenario, run_dir: Path, supervisor: Supervisor, *, quiet: bool) -> int:
    """Progress while the run goes, then the summary and the exit code."""
    bar = ProgressBar(scenario.duration_ns, enabled=not quiet)
    supervisor.wait(bar.update, bar.note)
    bar.close()
    result, cause = dict(supervisor.result), supervisor.cause()
    dropped = supervisor.dropped()  # with a program's own words (a result may be absent)
    if dropped:
        result["why_dropped"] = dropped
    if cause:
        result["error"] = cause
    record_settings(scenario, run_dir, result.get("settings"))
    codes = {n: c.proc.returncode for n, c in supervisor.services.items()}
    if int(result.get("ticks_done", 0)) > 0:  # type: ignore[call-overload]
        codes |= after_run(scenario, run_dir)  # run.rrd and dataset exports, from the files
    return summarise(
        scenario,
        run_dir,
        result,
        supervisor.conductor.proc.returncode,
        codes,
        stopped=supervisor.stopped,
        lingered=supervisor.lingered,
        after_fault=supervisor.after_fault,
        progress=supervisor.progress,
    )


def record_settings(scenario: Scenario, run_dir: Path, applied: object) -> None:
    """The run folder's scenario.json gets the settings timeline of the run (the scenario's
    own, those due after it ended included, and every `catabot set`, at the ticks they took
    effect), so running it again replays the same changes and records the same bytes, and
    an interrupted run's is the whole experiment. Untouched without changes."""
    if not isinstance(applied, list) or applied == scenario.model_dump(mode="json")["settings"]:
        return
    data = scenario.model_dump(mode="json") | {"settings": applied}
    try:
        resolved = parse_scenario(data, source="the run's settings")
        (run_dir / "scenario.json").write_text(scenario_json(resolved))
    except (CataBotError, OSError) as exc:
        print(f"catabot run: the settings timeline was not recorded: {exc}", file=sys.stderr)
