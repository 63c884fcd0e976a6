"""`catabot run --set FIELD=VALUE`: one scenario field changed for one run, the file kept.

Why: a lab's or a sweep's runs differ in a gain, a current or a sea; editing the JSON for each
loses which run had which value. A field is a dotted path through the resolved scenario
(every default filled in), list items by index: `water.current.velocity_mps=[0.5,0]`,
`vessels.0.controller.args=["--gain","2"]`, `water.waves.preset=medium`. The value is JSON;
a bare word that is no JSON is taken as a string (`name=lab3`), and so is any value for a
field that holds a string (`name=2024-lab`, `name=0.5`: a run named after a swept value).
The changed scenario is checked as a whole, as the file is, and the run folder's
scenario.json records the result. A field that a flag of its own also sets (`--seed`) is
refused: which one won was not said.
"""

from __future__ import annotations

import json
from typing import Any

from catabot.config.base import ConfigError, did_you_mean

JSONISH = '[{"'  # a value starting so was meant as JSON: its error is told


class OverrideError(ConfigError):
    """A `--set` that names no field of the scenario, or whose value is malformed JSON."""


def apply(
    data: dict[str, Any], items: list[str], *, flagged: dict[str, str] | None = None
) -> list[str]:
    """Each `FIELD=VALUE` of `items` set in `data` (a scenario's dump), in order; the flags
    as the error messages name them. `flagged`: fields a flag of their own gives (field:
    that flag), which a `--set` may not give as well."""
    flags, flagged = [], flagged or {}
    for item in items:
        path, text = _split(item)
        where = ".".join(path)
        if where in flagged:
            raise OverrideError(f"--set {item}: {where} is given by {flagged[where]} too (which "
                                "one wins was not said): give it once")  # fmt: skip
        _set(data, path, text, item=item)
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


def _set(data: dict[str, Any], path: list[str], text: str, *, item: str) -> None:
    """`data` at `path` becomes what `text` stands for (a field holding a string takes the
    text as it is); every step but the last must exist, but within a sensor's `params`,
    which hold only what the file gave (its type's model checks them, and names the keys)."""
    node: Any = data
    for depth, step in enumerate(path[:-1]):
        node = _step(node, step, path[: depth + 1], item=item)
        if node is None:
            raise OverrideError(f"--set {item}: {'.'.join(path[: depth + 1])} is not set in the "
                                "scenario: set it whole (--set FIELD={...})")  # fmt: skip
    last, where = path[-1], ".".join(path)
    if isinstance(node, list):
        key: Any = _index(node, last, where, item=item)
    elif isinstance(node, dict):
        if last not in node and not _in_params(path):
            raise OverrideError(_unknown(item, where, last, node))
        key = last
    else:
        raise OverrideError(f"--set {item}: {'.'.join(path[:-1])} is a value, not a section")
    old = node[key] if isinstance(node, list) or key in node else None
    node[key] = text if isinstance(old, str) else _value(text, item)


def _in_params(path: list[str]) -> bool:
    return "params" in path[:-1]


def _step(node: Any, key: str, path: list[str], *, item: str) -> Any:
    where = ".".join(path)
    if isinstance(node, list):
        return node[_index(node, key, where, item=item)]
    if not isinstance(node, dict):
        raise OverrideError(f"--set {item}: {where.rpartition('.')[0]} is a value, not a section")
    if key not in node and _in_params([*path, ""]) and path[-1] != "params":
        node[key] = {}  # a section of params the file left to its defaults
    if key not in node:
        raise OverrideError(_unknown(item, where, key, node))
    return node[key]


def _index(node: list[Any], key: str, where: str, *, item: str) -> int:
    if not key.isdigit() or int(key) >= len(node):
        raise OverrideError(f"--set {item}: {where}: a list of {len(node)}, so an index from 0 "
                            f"to {len(node) - 1}")  # fmt: skip
    return int(key)


def _unknown(item: str, where: str, key: str, node: dict[str, Any]) -> str:
    near = did_you_mean(key, node)
    hint = near or (f"its fields: {', '.join(sorted(node))}" if node else "it holds no field")
    return f"--set {item}: the scenario has no field {where} ({hint})"
