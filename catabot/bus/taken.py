"""The free commands physics took at a tick, carried in that tick's `BodyStates.commands`.

A command from outside the lockstep (tick -1) takes effect at whatever tick physics is at
when it arrives. The recorder heard it at its own tick, up to a window of ticks away (a
command recorded 0.1 s before the state it was computed from, 10-18 ticks off from run to
run), so physics says which it took: each entry is `<key relative to the world> <JSON of the
message>`, JSON so that any language reads it, floats exact (Python's shortest repr). The
recorder writes each at the tick it took effect, as tick k - 1 stamped k dt, DESIGN.md §6.
"""

from __future__ import annotations

import dataclasses
import json
from collections.abc import Mapping

from catabot.bus import codec
from catabot.bus.messages import MESSAGE_TYPES, SCHEMA_VERSION, Message


def entry(key: str, msg: Message) -> str:
    """One taken command as `BodyStates.commands` carries it (`key`: relative)."""
    body = {"type": msg.TYPE} | dataclasses.asdict(msg)
    return f"{key} {json.dumps(body, separators=(',', ':'))}"


def taken(text: str, kinds: Mapping[str, type[Message]]) -> tuple[str, Message]:
    """(relative key, message) of an entry; ValueError naming what is wrong. `kinds`: each
    command key this world has, with its message type."""
    key, _, body = text.partition(" ")
    kind = kinds.get(key)
    if kind is None:
        raise ValueError(f"taken command on {key[:80]!r}: no command key of this world")
    try:
        fields = json.loads(body)
        wire = fields.get("type") if isinstance(fields, dict) else None
        if MESSAGE_TYPES.get(str(wire)) is not kind:
            raise ValueError(f"a {wire!r} is no {kind.TYPE}")
        return key, codec.decode(codec.pack({"v": SCHEMA_VERSION} | fields), kind)
    except (ValueError, codec.CodecError) as exc:
        raise ValueError(f"taken command on {key!r}: {exc}") from None
