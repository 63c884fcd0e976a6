"""`catabot get`, `catabot set` and `catabot snapshot`: the settings menu of a running
simulation, over Zenoh (the conductor's settings desk, catabot/run/settings_desk.py).

Each opens its own session with the shared connection flags, finds the world (`--world`, or
the one simulation that answers), asks, prints, and exits 0, or 2 with one line saying why
(no simulation answered, an unknown key, a value not allowed), never a traceback.
"""

from __future__ import annotations

import argparse
import json
import os
import queue
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np
import zenoh
from PIL import Image

from catabot.bus import codec
from catabot.bus.keys import ROOT, Keys
from catabot.bus.messages import CameraFrame
from catabot.bus.session import (
    add_connection_args,
    check_router,
    connection_from_args,
    open_session,
    until_answered,
)
from catabot.config.live import SettingError, parse_value
from catabot.errors import CataBotError
from catabot.run.answer import OneLineParser, answered


class AskError(CataBotError, RuntimeError):
    """No simulation answered, or it refused; the message is what the user reads."""


def _parser(prog: str) -> argparse.ArgumentParser:
    parser = OneLineParser(prog=f"catabot {prog}")
    parser.add_argument("--world", help="the simulation's world name (default: the one running)")
    parser.add_argument("--timeout", type=float, default=5.0, help="seconds to wait (default 5)")
    add_connection_args(parser)
    return parser


def _ask(
    session: zenoh.Session, selector: str, timeout: float, payload: str | None = None
) -> list[tuple[str, Any]]:
    """Every answer to one query: (key, decoded JSON); AskError for an error reply."""
    answers = []
    for reply in session.get(selector, payload=payload, timeout=timeout):
        if reply.ok is not None:
            answers.append((str(reply.ok.key_expr), _json(reply.ok.payload.to_bytes())))
        else:
            body = _json(reply.err.payload.to_bytes() if reply.err is not None else b"")
            raise AskError(str(body.get("error", body) if isinstance(body, dict) else body))
    return answers


def _json(data: bytes) -> Any:
    try:
        return json.loads(data.decode("utf-8"))
    except (UnicodeDecodeError, ValueError):
        return data.decode("utf-8", "replace")


def _settings(session: zenoh.Session, world: str | None, timeout: float) -> dict[str, Any]:
    """The settings desk's answer, from `world` or the only simulation that answers."""
    selector = Keys(world).config("settings") if world else f"{ROOT}/*/config/settings"
    answers = until_answered(
        lambda left: [a for _, a in _ask(session, selector, left) if isinstance(a, dict)],
        timeout,
    )
    worlds = sorted({str(a.get("world")) for a in answers})
    if not answers:
        where = f"world {world!r}" if world else "any world"
        raise AskError(
            f"no running simulation of {where} answered within {timeout:g} s (is one running? "
            "`catabot run --listen tcp/127.0.0.1:7447` fixes its endpoint; pass --connect "
            "tcp/127.0.0.1:7447 here)"
        )
    if len(worlds) > 1:
        raise AskError(f"several simulations answer ({', '.join(worlds)}): choose one with --world")
    return answers[0]


def _session(args: argparse.Namespace) -> zenoh.Session:
    conn = connection_from_args(args)
    for endpoint in conn.connect:  # one line, not Zenoh's error from deep inside
        check_router(endpoint)
    session = open_session(conn)
    time.sleep(0.3)  # peers meet before the first query (a router answers at once)
    return session


def get_main(argv: list[str]) -> int:
    parser = _parser("get")
    parser.add_argument("key", nargs="?", help="one setting (default: every setting)")
    parser.add_argument("--json", action="store_true", help="the whole answer as JSON")
    args = parser.parse_args(argv)

    def ask(session: zenoh.Session) -> None:
        answer = _settings(session, args.world, args.timeout)
        settings, allowed = answer.get("now", answer["settings"]), answer["allowed"]
        if args.json:
            print(json.dumps(answer if args.key is None else settings.get(args.key), indent=2))
        elif args.key is not None:
            if args.key not in settings:
                raise AskError(
                    f"unknown setting {args.key!r}; this run's settings: {', '.join(settings)}"
                )
            print(json.dumps(settings[args.key]))
        else:
            for key, value in settings.items():
                print(f"{key} = {json.dumps(value)}    # {allowed.get(key, '')}{_due(answer, key)}")

    return _run("get", args, ask)


def _due(answer: dict[str, Any], key: str) -> str:
    """The changes of `key` the desk says are still to come (a timeline's later entries
    were shown as if in force already)."""
    later = [c for c in answer.get("due", []) if c["key"] == key]
    return "".join(f"; {json.dumps(c['value'])} from t = {c['t_s']:g} s" for c in later)


def set_main(argv: list[str]) -> int:
    parser = _parser("set")
    parser.add_argument("key", help="a setting (catabot get lists them)")
    parser.add_argument(
        "value", nargs="+", help="its value: a number, true/false (on/off), a word, JSON "
        "([0.3, 0.1] needs no quotes: the words are joined)",
    )  # fmt: skip
    args = parser.parse_args(argv)
    try:  # before any session: a value that cannot be read is the typist's to fix
        value = parse_value(" ".join(args.value))
    except SettingError as exc:
        print(f"catabot set: {exc}", file=sys.stderr)
        return 2

    def ask(session: zenoh.Session) -> None:
        world = args.world or _settings(session, None, args.timeout)["world"]
        request = json.dumps({"key": args.key, "value": value})
        answers = _ask(session, Keys(world).config("set"), args.timeout, request)
        if not answers:  # a secure profile's router drops an observer's query unanswered
            login = args.zenoh_config or os.environ.get("ZENOH_CONFIG")
            hint = " (an observer's login may read settings, not change them)" if login else ""
            raise AskError(f"world {world!r} did not answer within {args.timeout:g} s{hint}")
        done = answers[0][1]
        print(f"{done['key']} = {json.dumps(done['value'])} from tick {done['tick']} "
              f"(t = {done['t_s']:g} s)")  # fmt: skip

    return _run("set", args, ask)


def snapshot_main(argv: list[str]) -> int:
    parser = _parser("snapshot")
    parser.add_argument("--vessel", help="the camera's vessel (default: the first camera's)")
    parser.add_argument("--camera", help="the camera's name (default: the vessel's first camera)")
    parser.add_argument(
        "-o", "--output", help="PNG file (default snapshot_<vessel>_<camera>_<tick>.png)"
    )
    args = parser.parse_args(argv)

    def ask(session: zenoh.Session) -> None:
        answer = _settings(session, args.world, args.timeout)
        vessel, camera = _camera(answer["settings"], args.vessel, args.camera)
        frame = _next_frame(session, Keys(answer["world"]).sensor(vessel, camera), args.timeout)
        if frame.color.size == 0:
            raise AskError(f"camera {vessel}/{camera} has its colour output off: "
                           f"catabot set sensor.{vessel}.{camera}.outputs.color true")  # fmt: skip
        path = Path(args.output or f"snapshot_{vessel}_{camera}_{frame.tick}.png")
        Image.fromarray(np.ascontiguousarray(frame.color)).save(path, format="PNG")
        print(f"{path} ({vessel}/{camera}, tick {frame.tick}, t = {frame.stamp_ns / 1e9:g} s)")

    return _run("snapshot", args, ask)


def _camera(settings: dict[str, Any], vessel: str | None, camera: str | None) -> tuple[str, str]:
    """(vessel, camera) from the flags and the cameras the settings name."""
    cameras = [k.removeprefix("sensor.").removesuffix(".outputs.color") for k in settings
               if k.startswith("sensor.") and k.endswith(".outputs.color")]  # fmt: skip
    for name in cameras:
        for cut in [i for i, ch in enumerate(name) if ch == "."]:
            v, c = name[:cut], name[cut + 1 :]
            if vessel in (None, v) and camera in (None, c):
                return v, c
    wanted = f"{vessel or '*'}.{camera or '*'}"  # spelt as the cameras' settings keys
    raise AskError(f"no camera {wanted} in this run (cameras: {', '.join(cameras) or 'none'})")


def _next_frame(session: zenoh.Session, key: str, timeout: float) -> CameraFrame:
    """The next frame published on `key` (skipping anything that is not one)."""
    frames: queue.SimpleQueue[bytes] = queue.SimpleQueue()
    sub = session.declare_subscriber(key, lambda s: frames.put(s.payload.to_bytes()))
    limit = time.monotonic() + timeout
    try:
        while (left := limit - time.monotonic()) > 0:
            try:
                return codec.decode(frames.get(timeout=left), CameraFrame)
            except codec.CodecError:
                continue
            except queue.Empty:
                break
    finally:
        sub.undeclare()
    raise AskError(f"no frame on {key} within {timeout:g} s (is the camera on? catabot get)")


def _run(prog: str, args: argparse.Namespace, ask: Any) -> int:
    return answered(prog, lambda: _asked(args, ask))


def _asked(args: argparse.Namespace, ask: Any) -> None:
    session = _session(args)
    try:
        ask(session)
    finally:
        session.close()
