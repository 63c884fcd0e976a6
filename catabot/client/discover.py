"""Finding a running world: the conductor's `world/info` queryable, asked until it answers.

Peers need a moment to meet after a session opens (a router answers at once), and the
conductor serves the queryable once it has resolved the world, so the query is repeated
until `timeout_s`. With no world named, `catabot/*/world/info` finds every running world:
exactly one must answer, or the error lists them.
"""

from __future__ import annotations

import json
from typing import Any

import zenoh

from catabot.bus.keys import KeyNameError, Keys, world_infos
from catabot.bus.session import until_answered
from catabot.client.errors import ClientError, SeveralWorlds, SimulatorNotFound
from catabot.client.info import WorldInfo, parse


def find_world(
    session: zenoh.Session, world: str | None, timeout_s: float, where: str
) -> WorldInfo:
    """The `WorldInfo` of `world` (or of the only world running); `where` names the
    endpoints in the error."""
    selector = Keys(world).world_info() if world else world_infos()
    answers = until_answered(lambda left: _ask(session, selector, left), timeout_s)
    others = sorted(_ask(session, world_infos(), 1.0)) if world and not answers else []
    if others:  # a misspelt world beside a running one is not "is catabot run running?"
        running = ", ".join(others)
        raise SimulatorNotFound(
            f"no simulation of world {world!r} answered ({where}); running there: {running}"
        )
    if not answers:
        what = f"world {world!r}" if world else "any world"
        raise SimulatorNotFound(
            f"no simulation of {what} answered on {selector} within {timeout_s:g} s "
            f"({where}); is `catabot run` running, and does it listen where this client "
            "connects (`catabot run --listen tcp/127.0.0.1:7447`, then connect="
            '["tcp/127.0.0.1:7447"] or --connect tcp/127.0.0.1:7447)?'
        )
    worlds = sorted(answers)
    if len(worlds) > 1:
        raise SeveralWorlds(
            f"several simulations answer ({', '.join(worlds)}): choose one with world= (--world)"
        )
    key, data = answers[worlds[0]]
    return parse(data, key)


def _ask(session: zenoh.Session, selector: str, timeout_s: float) -> dict[str, tuple[str, Any]]:
    """World name -> (key, decoded answer) of every valid reply (error replies and
    non-JSON are skipped: they name no world)."""
    out: dict[str, tuple[str, Any]] = {}
    # Every reply, not Zenoh's default consolidation (one per key): a second answer on a
    # world's key must be seen to be refused.
    replies = session.get(selector, timeout=timeout_s, consolidation=zenoh.ConsolidationMode.NONE)
    for reply in replies:
        if reply.ok is None:
            continue
        key = str(reply.ok.key_expr)
        try:
            data = json.loads(reply.ok.payload.to_bytes().decode("utf-8"))
        except (UnicodeDecodeError, ValueError, RecursionError):
            continue
        if not isinstance(data, dict) or not _answers_its_own_key(data.get("world"), key):
            continue
        name = data["world"]
        if name in out and _static(out[name][1]) != _static(data):
            raise ClientError(
                f"two different answers on {key}: one is not its conductor's (on an open "
                "network anyone may answer; the secure profile lets only the conductor)"
            )
        out[name] = (key, data)
    return out


def _static(data: dict[str, Any]) -> dict[str, Any]:
    """An answer without what changes between two queries (the clock's grant)."""
    return {k: v for k, v in data.items() if k != "granted"}


def _answers_its_own_key(name: object, key: str) -> bool:
    """Whether an answer on `key` names the world that key belongs to."""
    try:
        return isinstance(name, str) and key == Keys(name).world_info()
    except KeyNameError:
        return False
