"""`catabot run --set FIELD=VALUE`: one scenario field changed for one run, as if the file had
said so.

Why: a lab's or a sweep's runs differ in a gain, a current or a sea; editing the JSON for each
loses which run had which value. A field is a dotted path through the scenario, list items
by index: `water.current.velocity_mps=[0.5,0]`, `vessels.0.controller.args=["--gain","2"]`,
`water.waves.preset=medium`. The path is checked against the resolved scenario (every
default filled in: a typo gets "did you mean"), the value is set in the file's own data (a
preset then fills what the file left to it; set in the resolved scenario, `preset=medium`
lost to the calm sea's filled-in height). The value is JSON; a bare word that is no JSON is
a string, and so is any value for a field that holds a string (`name=2024-lab`). The result
is checked as the file is, and the run folder's scenario.json records it. A field that a
flag of its own also gives (`--seed`) is refused: which one won was not said.
"""

from __future__ import annotations

import copy
import json
from typing import Any

from catabot.config.base import ConfigError, did_you_mean

JSONISH = '[{"'  # a value starting so was meant as JSON: its error is told


class OverrideError(ConfigError):
    """A `--set` that names no field of the scenario, or whose value is malformed JSON."""


def apply(
    data: dict[str, Any],
    items: list[str],
    *,
    resolved: dict[str, Any],
    flagged: dict[str, str] | None = None,
) -> list[str]:
    """Each `FIELD=VALUE` of `items` set in `data` (the file's own), in order, each path
    checked against `resolved` (the same scenario with its defaults); the flags as error
    messages name them. `flagged`: fields a flag of their own gives (field: that flag)."""
    flags, flagged = [], flagged or {}
    for item in items:
        path, text = _split(item)
        where = ".".join(path)
        both = [f for f in flagged if f"{where}.".startswith(f"{f}.") or f.startswith(f"{where}.")]
        if both:  # the field itself, a part of it, or a whole it is part of (`traffic={...}`)
            raise OverrideError(f"--set {item}: {both[0]} is given by {flagged[both[0]]} too "
                                "(which one wins was not said): give it once")  # fmt: skip
        _set(data, resolved, path, text, item=item)
        _set(resolved, copy.deepcopy(resolved), path, text, item=item)  # for the next --set
        flags.append(f"--set {item}")
    return flags


def _split(item: str) -> tuple[list[str], str]:
    field, sep, text = item.partition("=")
    if not sep or not field.strip():
        raise OverrideError(
            f"--set {item!r}: give FIELD=VALUE, e.g. --set water.current.velocity_mps=[0.5,0]"
        )
    return field.strip().split("."), text.strip()


def _value(text: str, item: str) -> Any:
    try:
        return json.loads(text)
    except json.JSONDecodeError as exc:
        if text[:1] in JSONISH:
            raise OverrideError(f"--set {item}: the value is not JSON ({exc.msg} at column "
                                f"{exc.colno})") from None  # fmt: skip
        return text  # a bare word: a string (the field's check says if it may be one)


def _set(data: Any, like: Any, path: list[str], text: str, *, item: str) -> None:
    """`data` at `path` becomes what `text` stands for (a field holding a string takes the
    text as it is). `like` is the resolved scenario, walked beside it: a step must exist
    there, but within a sensor's `params`, which the type's model checks; `data` gets the
    sections the file left out."""
    for depth, step in enumerate(path[:-1]):
        where = ".".join(path[: depth + 1])
        like = _step(like, step, where, params="params" in path[:depth], item=item)
        if like is None:
            raise OverrideError(f"--set {item}: {where} is not set in the scenario: set it "
                                "whole (--set FIELD={...})")  # fmt: skip
        data = _into(data, step, like)
    last, where = path[-1], ".".join(path)
    old = _step(like, last, where, params="params" in path[:-1], item=item, leaf=True)
    key: Any = int(last) if isinstance(data, list) else last
    data[key] = text if isinstance(old, str) and text != "null" else _value(text, item)


def _step(node: Any, key: str, where: str, *, params: bool, item: str, leaf: bool = False) -> Any:
    """The resolved scenario's value at `key` of `node` (None for a new key of `params`)."""
    if isinstance(node, list):
        return node[_index(node, key, where, item=item)]
    if not isinstance(node, dict):
        raise OverrideError(f"--set {item}: {where.rpartition('.')[0]} is a value, not a section")
    if key not in node and not params:
        raise OverrideError(_unknown(item, where, key, node))
    return node.get(key, None if leaf else {})


def _into(data: Any, key: str, like: Any) -> Any:
    """The file's section at `key`, made (like the resolved one's kind) where it had none."""
    if isinstance(data, list):
        return data[int(key)]
    if key not in data or data[key] is None:
        data[key] = copy.deepcopy(like) if isinstance(like, list) else {}
    return data[key]


def _index(node: list[Any], key: str, where: str, *, item: str) -> int:
    if not key.isdigit() or int(key) >= len(node):
        span = f"an index from 0 to {len(node) - 1}" if node else "no index (it is empty)"
        ids = [n.get("id") if isinstance(n, dict) else None for n in node]
        named = f": {key!r} is {where.rpartition('.')[0]}.{ids.index(key)}" if key in ids else ""
        raise OverrideError(f"--set {item}: {where}: a list of {len(node)}, so {span}{named}")
    return int(key)


def _unknown(item: str, where: str, key: str, node: dict[str, Any]) -> str:
    near = did_you_mean(key, node)
    hint = near or (f"its fields: {', '.join(sorted(node))}" if node else "it holds no field")
    return f"--set {item}: the scenario has no field {where} ({hint})"
