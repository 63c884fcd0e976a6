"""`catabot view`: a recorded run or a running simulation in the rerun viewer.

    catabot view RUN_FOLDER                    replay run.mcap into the native viewer
    catabot view RUN_FOLDER --web              ... into the web viewer (prints its address)
    catabot view RUN_FOLDER --save out.rrd     ... into a file (what `recording.rerun` does)
    catabot view --connect ENDPOINT [SOURCE]   attach to a running simulation; SOURCE is its
                                               run folder or scenario (default: the world
                                               running there, asked for: --world NAME)

`catabot run --view [web]` starts the live form beside the run. The web viewer is served
until Ctrl-C (a browser that opens it late still gets everything logged so far). Exit codes:
0 done, 2 refused (no such run folder, no run.mcap, a bad scenario), with one line saying why.
"""

from __future__ import annotations

import argparse
import logging
import os
import signal
import sys
import time
from pathlib import Path
from typing import Any
from urllib.parse import quote

import rerun as rr
import zenoh

from catabot.bus.messages import End
from catabot.bus.session import (
    SessionError,
    add_connection_args,
    connection_from_args,
    free_port,
)
from catabot.bus.session import open_session as open_zenoh
from catabot.client.discover import find_world
from catabot.config.load import load_scenario, parse_scenario
from catabot.errors import CataBotError
from catabot.run.answer import OneLineParser, output_file
from catabot.run.ending import end_reason, finished, run_record
from catabot.run.recorded import RecordedRun
from catabot.world.world import World
from services.viewer.blueprint import blueprint
from services.viewer.live import LiveView
from services.viewer.replay import replay

log = logging.getLogger("viewer")
FIND_S = 10.0  # how long --connect without a SOURCE asks for the running world


def parser() -> argparse.ArgumentParser:
    p = OneLineParser(prog="catabot view", description=__doc__.split("\n")[0])
    p.add_argument(
        "source",
        nargs="?",
        help="a run folder (with --connect: the running run's folder or its scenario file)",
    )
    add_connection_args(p)
    p.add_argument("--world", help="with --connect and no SOURCE: which running world")
    p.add_argument("--web", action="store_true", help="serve the web viewer, do not spawn one")
    p.add_argument("--web-port", type=int, default=0, help="web viewer port (default: free)")
    p.add_argument("--grpc-port", type=int, default=0, help="data port (default: free)")
    p.add_argument("--save", metavar="FILE", help="write an .rrd file instead of showing it")
    p.add_argument("--no-hold", action="store_true", help="web: stop serving when done")
    p.add_argument("--ready-file", type=Path, help=argparse.SUPPRESS)  # for catabot run
    return p


def recording(world: World, args: argparse.Namespace, *, live: bool) -> rr.RecordingStream:
    """A recording on `sim_time` only (no wall-clock timelines), sent where `args` say. Its
    id is the run folder's name where there is one: the viewer merges recordings of one id,
    so two runs of a scenario opened side by side were one recording."""
    folder = _run_folder(args)
    name = folder.resolve().name if folder is not None else world.scenario.name
    rec = rr.RecordingStream("catabot", recording_id=name, send_properties=False)
    rec.set_log_time_enabled(False)
    rec.set_log_tick_enabled(False)
    layout = blueprint(world, live=live)
    if args.save:
        rec.save(args.save, default_blueprint=layout)
    elif args.web:
        print(f"rerun web viewer: {_serve_web(rec, layout, args)}", flush=True)
    else:
        _spawn(rec, layout)
    return rec


def _spawn(rec: rr.RecordingStream, layout: Any) -> None:
    """The desktop viewer, from this Python's own environment: a venv not activated has its
    `rerun` off PATH (rerun's traceback said "pip install rerun-sdk"), and with no display
    the viewer died and this process hung past SIGTERM."""
    if sys.platform.startswith("linux") and not (
        os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")
    ):
        raise ViewerError("no display here (DISPLAY and WAYLAND_DISPLAY are unset): use --web "
                          "for a browser, or --save FILE.rrd to open elsewhere")  # fmt: skip
    beside = Path(sys.executable).with_name("rerun")
    path = str(beside) if beside.is_file() else None
    try:
        rr.spawn(recording=rec, default_blueprint=layout, executable_path=path)
    except RuntimeError as exc:
        raise ViewerError(f"cannot start the rerun viewer ({exc}): use --web or --save") from None


def _serve_web(rec: rr.RecordingStream, layout: Any, args: argparse.Namespace) -> str:
    """Serve the recording and the web viewer on the asked ports, or on free ones (rerun's
    defaults, 9090 and 9876, clashed with a second viewer: a traceback); the page's URL,
    its `url` parameter escaped (a bare `+` reads as a space)."""
    web, grpc_port = args.web_port or free_port(), args.grpc_port or free_port()
    try:
        grpc = rec.serve_grpc(grpc_port=grpc_port, default_blueprint=layout)
        rr.serve_web_viewer(web_port=web, open_browser=False, connect_to=grpc)
    except RuntimeError as exc:  # rerun's "Failed to create server: Address already in use"
        raise ViewerPortError(f"--web-port {web} / --grpc-port {grpc_port}: {exc}") from None
    return f"http://127.0.0.1:{web}/?url={quote(grpc, safe=':/')}"


class ViewerError(CataBotError, OSError):
    """The viewer could not be shown: no display, no viewer program."""


class ViewerPortError(ViewerError):
    """The web viewer could not serve on its ports."""


def _run_folder(args: argparse.Namespace) -> Path | None:
    """SOURCE when it is a run folder (not a scenario file, not absent)."""
    return Path(args.source) if args.source and Path(args.source).is_dir() else None


def _world(args: argparse.Namespace, session: zenoh.Session) -> World:
    """SOURCE's world, else the one running where it connects (its world/info: a Gym
    episode's run has no folder to name; the default scenario's world never matched it)."""
    source = args.source
    if source is None:
        where = f"connect {list(args.connect)}"
        info = find_world(session, args.world, FIND_S, where)
        return World.resolve(parse_scenario(info.scenario, source=f"world {info.name}"))
    folder = _run_folder(args)
    if folder is not None:
        source = str(folder / "scenario.json")
    return World.resolve(load_scenario(source))


def _live(args: argparse.Namespace) -> tuple[rr.RecordingStream, int]:
    session = open_zenoh(connection_from_args(args))
    try:
        world = _world(args, session)
        view = LiveView(session, world)  # subscribed before anything is logged
        rec = recording(world, args, live=True)
        if args.ready_file is not None and view.linked(session):  # not otherwise: a view
            args.ready_file.touch()  # come late waited 20 s; catabot run starts its services
        end = view.run(rec, _run_folder(args))
        rec.flush()
    finally:
        session.close()
    text, code = _ending(args, end, view)
    print(text, file=sys.stderr if code else sys.stdout, flush=True)
    shown = ", ".join(f"{n} {what}" for what, n in sorted(view.shown.items()))
    cpu = time.process_time()  # every thread of the viewer process, start-up included
    print(f"shown: {shown or 'nothing'}; viewer CPU {cpu:.1f} s", flush=True)
    return rec, code


def _ending(args: argparse.Namespace, end: End | None, view: LiveView) -> tuple[str, int]:
    """How the view's run ended, and the exit code: its End, or, the link lost first, its
    run folder's word (exit 2 when no folder says it, or when nothing ever answered)."""
    if end is not None:
        return f"run ended: {end.reason}", 0
    if not view.lost:
        return "stopped before the run ended", 0
    folder, where = _run_folder(args), list(args.connect)
    record = run_record(folder) if folder is not None else None
    if not finished(record):
        return (f"catabot view: the run at {where} went away (or never answered) before its "
                "end reached the view, and no run folder says how it ended; what it drew is "
                "kept"), 2  # fmt: skip
    reason = end_reason(record, None)
    if not view.ever_linked:  # a finished run's folder, and an endpoint nobody listens on
        return (f"catabot view: nothing answers at {where}; the run in {folder} has ended "
                f"({reason}): `catabot view {folder}` replays it"), 2  # fmt: skip
    return f"run ended: {reason} (its run folder says: the view lost it before its End came)", 0


def _replay(args: argparse.Namespace) -> rr.RecordingStream:
    run = RecordedRun(args.source)
    rec = recording(run.world, args, live=False)
    replay(run, rec)
    rec.flush()
    return rec


def _serve(args: argparse.Namespace, rec: rr.RecordingStream) -> None:
    """The web viewer lives in this process, its data in `rec`'s server (which closes with
    `rec`): keep both up until Ctrl-C or SIGTERM."""
    if args.save:  # what a --save wrote, and where (it said nothing: `catabot run` names it)
        rec.flush()
        size = Path(args.save).stat().st_size / 1e6 if Path(args.save).is_file() else 0.0
        print(f"saved {args.save} ({size:.1f} MB): rerun {args.save}", flush=True)
    if not args.web or args.save or args.no_hold:
        return
    print("serving the web viewer until Ctrl-C", flush=True)
    try:
        while True:
            time.sleep(3600)
    except KeyboardInterrupt:
        pass


def main(argv: list[str] | None = None) -> int:
    logging.basicConfig(level=logging.INFO, format="%(name)s %(levelname)s %(message)s")
    args = parser().parse_args(argv)
    signal.signal(signal.SIGTERM, lambda *_: sys.exit(0))  # the launcher's stop: flush, exit
    if not args.connect and args.source is None:
        parser().error("give a RUN_FOLDER to replay, or --connect ENDPOINT to attach to a run")
    try:
        if args.save:
            output_file(args.save, flag="--save")  # before the replay, not after it
        rec, code = _live(args) if args.connect else (_replay(args), 0)
    except (CataBotError, SessionError) as exc:
        print(f"catabot view: {exc}", file=sys.stderr)
        return 2
    except OSError as exc:
        print(f"catabot view: {exc.filename or ''} {exc.strerror}", file=sys.stderr)
        return 2
    _serve(args, rec)  # a lost run's view too: what it drew is kept, saved or served
    return code


if __name__ == "__main__":
    sys.exit(main())
