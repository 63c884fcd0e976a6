"""The `catabot` command: run, service, router, scenario, secure, deploy, and the tools over
run folders (view, dataset, plot, results)."""

from __future__ import annotations

import argparse
import importlib
import json
import os
import signal
import sys
import threading
from pathlib import Path

from catabot.bus.session import Connection, SessionError, add_connection_args, open_session
from catabot.config.load import json_schema, model_schema
from catabot.config.notes import late_settings, late_steps, scenario_notes
from catabot.config.scenario import Scenario, WaterConfig
from catabot.config.vessel import VesselModel, VesselModelError, load_vessel_model
from catabot.errors import CataBotError
from catabot.run import compose, conduct, console, launcher, secure, settings_cli
from catabot.run.answer import OneLineParser, answered, output_file
from catabot.run.companions import VIEW_MODES
from catabot.run.generate import ONLY_GENERATE, generate
from catabot.run.generate import add_arguments as add_generate_arguments
from catabot.world.model_checks import displacement, model_notes
from catabot.world.traffic_notes import traffic_notes


def _run(args: argparse.Namespace) -> int:
    connect, configs = tuple(args.connect), None
    if args.secure:  # every process a client of the profile's router, with its own login
        configs = Path(args.secure)
        try:
            connect = connect or (secure.router_endpoint(configs),)
        except CataBotError as exc:
            print(f"catabot run: {exc}", file=sys.stderr)
            return 2
    if args.out is not None and args.run_dir is not None:
        print("catabot run: --out and --run-dir both name where the run goes: give one "
              "(--run-dir is the run folder itself)", file=sys.stderr)  # fmt: skip
        return 2
    opts = launcher.RunOptions(
        scenario=args.scenario,
        duration_s=args.duration,
        seed=args.seed,
        realtime=args.realtime,
        out=Path(args.out or "runs"),
        connect=connect,
        listen=args.listen,
        quiet=args.quiet,
        zenoh_configs=configs,
        view=args.view,
        sets=tuple(args.set),
        run_dir=Path(args.run_dir) if args.run_dir else None,
    )
    return launcher.run(opts)


def _schema(output: str | None, *, model: bool = False) -> str | None:
    text = json.dumps(model_schema() if model else json_schema(), indent=2) + "\n"
    if output is None:
        sys.stdout.write(text)
        return None
    output_file(output, flag="--output").write_text(text)
    return f"{output}: the {'vessel model' if model else 'scenario'}'s JSON Schema"


def _secure(args: argparse.Namespace) -> int:
    try:
        files = secure.init(
            Path(args.folder), clients=args.client, observers=args.observer, host=args.host,
            port=args.port, sensor_shards=args.sensor_shards, traffic_shards=args.traffic_shards,
        )  # fmt: skip
    except CataBotError as exc:
        print(f"catabot secure: {exc}", file=sys.stderr)
        return 2
    print(f"secure profile in {args.folder}: {len(files)} files; start its router with\n"
          f"  catabot router --zenoh-config {Path(args.folder) / 'router.json5'}")  # fmt: skip
    return 0


def _service(args: argparse.Namespace, rest: list[str]) -> int:
    names = ", ".join(["conductor", *launcher.SERVICE_MODULES])
    if args.name is None or args.name.startswith("-"):
        asked = args.name in ("-h", "--help") or not {"-h", "--help"}.isdisjoint(rest)
        print(f"usage: catabot service NAME --scenario FILE [flags]; NAME is one of {names} "
              "(`catabot service physics --help` lists its flags)",
              file=sys.stdout if asked else sys.stderr)  # fmt: skip
        return 0 if asked else 2
    if args.name == "conductor":
        conduct.exit_now(conduct.main(rest))
    module = launcher.SERVICE_MODULES.get(args.name)
    if module is None:
        print(f"catabot service: unknown service {args.name!r} (known: {names})", file=sys.stderr)
        return 2
    main = importlib.import_module(f"{module}.service").main
    return int(main(rest))


# fields a vessel model has and a scenario has not (`description` is any file's note)
MODEL_ONLY = frozenset(VesselModel.model_fields) - {*Scenario.model_fields, "description"}
TOOLS = {  # `catabot <tool> ...`: programs over a run folder, each in its own service folder
    "view": ("services.viewer.cli", "replay a run or attach to one in the rerun viewer"),
    "dataset": ("services.datasets.cli", "export a run: YOLO, COCO, SemanticKITTI, segmentation"),
    "plot": ("services.plots.cli", "plot a run: PNG figures and report.html"),
    "results": ("services.results.cli", "many runs in one table (a sweep): CSV for pandas"),
}
LIVE = {  # `catabot <command> ...` against a running simulation (its own flags and --help)
    "get": (settings_cli.get_main, "the settings of a running simulation"),
    "set": (settings_cli.set_main, "change a setting of a running simulation (rain, wind, ...)"),
    "snapshot": (settings_cli.snapshot_main, "save a camera's next colour image as PNG"),
}

DEPLOY = {  # `catabot deploy compose|probe ...`: containers (catabot/run/compose.py)
    "deploy": (compose.main, "containers: the compose file a scenario needs, health probes"),
}


def _tool(args: argparse.Namespace, rest: list[str]) -> int:
    """Hand the rest of the command line to the tool's own parser (its --help too)."""
    return int(importlib.import_module(TOOLS[args.command][0]).main(rest))


def _router(args: argparse.Namespace) -> int:
    """A Zenoh router on loopback unless told where (`--listen tcp/0.0.0.0:7447` for other
    machines), or as a config file says (`--zenoh-config`: TLS, credentials, access control)."""
    config = args.zenoh_config or os.environ.get("ZENOH_CONFIG")
    listen = tuple(args.listen) or (() if config else ("tcp/127.0.0.1:7447",))
    conn = Connection(connect=tuple(args.connect), listen=listen, mode="router", file=config)
    try:
        session = open_session(conn)
    except SessionError as exc:
        print(f"catabot router: {exc}", file=sys.stderr)
        return 2
    stop = threading.Event()  # SIGTERM (`docker stop`: PID 1 has no handler) or Ctrl-C
    for sig in (signal.SIGTERM, signal.SIGINT):
        signal.signal(sig, lambda *_: stop.set())
    where = ", ".join(listen) or f"the endpoints of {config}"  # told only once it may stop
    print(f"zenoh router listening on {where} (Ctrl-C to stop)", flush=True)
    while not stop.wait(0.2):  # a short wait: the handler runs between two
        pass
    session.close()
    return 0


def _scenario(args: argparse.Namespace) -> int:
    if args.action in ("schema", "model-schema"):
        model = args.action == "model-schema"
        return answered(f"scenario {args.action}", lambda: _schema(args.output, model=model))
    if args.action == "generate":
        return generate(args)
    if args.file is not None and _is_model(Path(args.file)):
        return answered("scenario validate", lambda: _valid_model(args.file))
    try:  # what `catabot run` checks before it starts anything, no less
        world = launcher.prepare(_validate_options(args))
    except CataBotError as exc:
        print(f"catabot scenario validate: {exc}", file=sys.stderr)
        return 2
    s = world.scenario
    counts = (
        f"{len(s.vessels)} vessel(s), {len(world.boat_ids)} traffic boat(s), "
        f"{len(world.buoys)} buoy(s), {len(world.sensors)} sensor(s), {s.ticks} ticks"
    )
    print(f"{args.file or 'default'}: valid ({counts})")
    for note in [*scenario_notes(s), *traffic_notes(world)]:
        print(note)
    for text in [*late_settings(s), *late_steps(s)]:  # at a run: the conductor's, physics'
        print(f"note: {text}")
    return 0


def _is_model(path: Path) -> bool:
    """A vessel model file given to `validate` (a field only a model has, no `vessels`):
    checked as one, not refused field by field as a scenario; by any such field, so a model
    missing its `hulls` hears that, not a dozen scenario fields."""
    try:
        data = json.loads(path.read_text())
    except (OSError, ValueError, RecursionError):
        return False  # the scenario path says what is wrong with it
    return isinstance(data, dict) and "vessels" not in data and bool(MODEL_ONLY & data.keys())


def _validate_options(args: argparse.Namespace) -> launcher.RunOptions:
    """`validate`'s flags as `catabot run` takes them (--seed and --set seed=... are refused
    together by both); generate's own flags are refused, not ignored."""
    wrong = [f"--{flag}" for flag in ONLY_GENERATE if getattr(args, flag) is not None]
    if wrong:
        raise launcher.LaunchError(f"{', '.join(wrong)}: only for `scenario generate`")
    return launcher.RunOptions(
        scenario=args.file, sets=tuple(args.set), seed=args.seed, duration_s=args.duration
    )


def _valid_model(file: str) -> str:
    """Valid, with what its figures imply (model_checks.py): a designer's unit slips pass
    every field's own limit."""
    model = load_vessel_model(str(Path(file).resolve()))
    density = WaterConfig().density_kg_m3  # a scenario's water: with it
    sinks = model.sinks_in(density)
    if sinks:
        raise VesselModelError(f"vessel model {file!r} {sinks}")
    notes = "".join(f"\nnote: {n}" for n in model_notes(model, source=file, density=density))
    return (f"{file}: a valid vessel model {model.name!r} ({model.mass_kg:g} kg, "
            f"{len(model.hulls)} hull(s), {len(model.thrusters)} thruster(s)); "
            f"{displacement(model, density)}{notes}")  # fmt: skip


def parser() -> OneLineParser:
    p = OneLineParser(prog="catabot", description=__doc__)
    sub = p.add_subparsers(dest="command", required=True)
    run = sub.add_parser("run", help="run a scenario: conductor and services as processes")
    run.add_argument("scenario", nargs="?", help="scenario file or bundled name (default: default)")
    run.add_argument("--duration", type=float, help="simulated seconds (overrides the scenario)")
    run.add_argument("--seed", type=int, help="the scenario's seed (a sweep's runs, one file)")
    run.add_argument(
        "--set", action="append", default=[], metavar="FIELD=VALUE",
        help="change one scenario field for this run (JSON value; repeatable), e.g. --set "
        "water.current.velocity_mps=[0.5,0] --set name=lab3",
    )  # fmt: skip
    run.add_argument(
        "--realtime", type=float, metavar="FACTOR",
        help="pace: 1.0 = wall clock; 0 = as fast as possible (the default, unless the "
        "scenario sets clock.realtime_factor)",
    )  # fmt: skip
    run.add_argument("--out", help="folder for run folders (default: runs)")
    run.add_argument("--run-dir", help="this run's folder itself, new or empty (instead of "
                     "--out's <name>-<time>): a script names its runs")  # fmt: skip
    run.add_argument(
        "--connect",
        action="append",
        default=[],
        metavar="ENDPOINT",
        help="use a zenoh router instead of the embedded peer mesh",
    )
    run.add_argument(
        "--listen",
        metavar="ENDPOINT",
        help="embedded mesh endpoint (default tcp/127.0.0.1:<free port>)",
    )
    run.add_argument("--quiet", action="store_true", help="no progress bar")
    run.add_argument(
        "--view",
        nargs="?",
        const="native",
        choices=VIEW_MODES,
        help="show the run live in rerun: the native viewer, or 'web' (served; prints its URL)",
    )
    run.add_argument(
        "--secure",
        metavar="DIR",
        help="the secure profile made by `catabot secure init DIR`: TLS, logins, access control",
    )
    sec = sub.add_parser("secure", help="the secure profile: certificates, logins, access control")
    sec.add_argument("action", choices=["init"])
    sec.add_argument("folder", help="where to write the profile's files")
    sec.add_argument("--client", action="append", default=[], help="a client that may command")
    sec.add_argument("--observer", action="append", default=[], help="a client that only reads")
    sec.add_argument(
        "--host", default="localhost", help="the router's host name (default localhost)"
    )
    sec.add_argument("--port", type=int, default=7447, help="the router's TLS port (default 7447)")
    shards = "logins for N sensor processes (a scenario's sensors.shards)"
    sec.add_argument("--sensor-shards", type=int, default=1, metavar="N", help=shards)
    guides = "logins for N traffic processes (a scenario's traffic.shards)"
    sec.add_argument("--traffic-shards", type=int, default=1, metavar="N", help=guides)
    svc = sub.add_parser(  # its --help is the service's own: `catabot service physics -h`
        "service", help="run one service (conductor, physics, ...) alone", add_help=False
    )
    svc.add_argument("name", nargs="?", help="conductor, or a service: physics, sensors, ...")
    rtr = sub.add_parser("router", help="run a zenoh router for distributed runs")
    add_connection_args(rtr, router=True)
    scen = sub.add_parser("scenario", help="scenario tools")
    scen.add_argument("action", choices=["schema", "model-schema", "validate", "generate"])
    scen.add_argument("file", nargs="?", help="scenario to validate")
    scen.add_argument("--output", "-o", help="write the schema (or generated scenario) here")
    scen.add_argument("--set", action="append", default=[], metavar="FIELD=VALUE",
                      help="changes, as catabot run --set (generate: to what it made)")  # fmt: skip
    add_generate_arguments(scen)
    for name, (_, text) in [*TOOLS.items(), *LIVE.items(), *DEPLOY.items()]:
        sub.add_parser(name, help=text, add_help=False)
    return p


def main(argv: list[str] | None = None) -> int:
    """Every command; Ctrl-C outside a run (which ends itself cleanly: supervisor.Stops)
    is exit 130 without a traceback, and a closed terminal or pipe ends no command early.
    A service is left as it is: its stdout is its launcher's pipe, and a conductor ends the
    run once nobody reads it (conduct.emit)."""
    if (sys.argv[1:] if argv is None else argv)[:1] == ["service"]:
        return _command(argv)
    with console.lasting():
        try:
            return _command(argv)
        except KeyboardInterrupt:
            print(file=sys.stderr)  # past the ^C
            return 130


def _command(argv: list[str] | None) -> int:
    args, rest = parser().parse_known_args(argv)
    if args.command == "service":
        return _service(args, rest)
    if args.command in TOOLS:
        return _tool(args, rest)
    if args.command in LIVE:
        return LIVE[args.command][0](rest)
    if args.command in DEPLOY:
        return DEPLOY[args.command][0](rest)
    parser().refuse_extra(args, rest)
    handlers = {"run": _run, "router": _router, "scenario": _scenario, "secure": _secure}
    return handlers[args.command](args)


if __name__ == "__main__":
    sys.exit(main())
