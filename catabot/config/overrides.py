"""`catabot run --set FIELD=VALUE`: one scenario field changed for one run, the file kept.

Why: a lab's or a sweep's runs differ in a gain, a current or a sea; editing the JSON for each
loses which run had which value. A field is a dotted path through the resolved scenario
(every default filled in), list items by index: `water.current.velocity_mps=[0.5,0]`,
`vessels.0.controller.args=["--gain","2"]`, `water.waves.preset=medium`. The value is JSON;
a bare word that is no JSON is taken as a string (`name=lab3`). The changed scenario is
checked as a whole, as the file is, and the run folder's scenario.json records the result.
"""

from __future__ import annotations

import json
from typing import Any

from catabot.config.base import ConfigError, did_you_mean

JSONISH = '[{"-0123456789.'  # a value starting so was meant as JSON: its error is told


class OverrideError(ConfigError):
    """A `--set` that names no field of the scenario, or whose value is malformed JSON."""


def apply(data: dict[str, Any], items: list[str]) -> list[str]:
    """Each `FIELD=VALUE` of `items` set in `data` (a scenario's dump), in order; the flags
    as the error messages name them."""
    flags = []
    for item in items:
        path, value = _split(item)
        _set(data, path, value, item=item)
        flags.append(f"--set {item}")
    return flags


def _split(item: str) -> tuple[list[str], Any]:
    field, sep, text = item.partition("=")
    if not sep or not field.strip():
        raise OverrideError(
            f"--set {item!r}: give FIELD=VALUE, e.g. --set water.current.velocity_mps=[0.5,0]"
        )
    return field.strip().split("."), _value(text.strip(), item)


def _value(text: str, item: str) -> Any:
    try:
        return json.loads(text)
    except json.JSONDecodeError as exc:
        if text[:1] in JSONISH and text not in ("", "-"):
            raise OverrideError(f"--set {item}: the value is not JSON ({exc.msg} at column "
                                f"{exc.colno})") from None  # fmt: skip
        return text  # a bare word: a string


def _set(data: dict[str, Any], path: list[str], value: Any, *, item: str) -> None:
    """`data` at `path` becomes `value`; every step but the last must exist."""
    node: Any = data
    for depth, key in enumerate(path[:-1]):
        node = _step(node, key, ".".join(path[: depth + 1]), item=item)
        if node is None:
            raise OverrideError(f"--set {item}: {'.'.join(path[: depth + 1])} is not set in the "
                                "scenario: set it whole (--set FIELD={...})")  # fmt: skip
    last = path[-1]
    if isinstance(node, list):
        node[_index(node, last, ".".join(path), item=item)] = value
    elif isinstance(node, dict):
        if last not in node:
            raise OverrideError(_unknown(item, ".".join(path), last, node))
        node[last] = value
    else:
        raise OverrideError(f"--set {item}: {'.'.join(path[:-1])} is a value, not a section")


def _step(node: Any, key: str, where: str, *, item: str) -> Any:
    if isinstance(node, list):
        return node[_index(node, key, where, item=item)]
    if not isinstance(node, dict):
        raise OverrideError(f"--set {item}: {where.rpartition('.')[0]} is a value, not a section")
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
    hint = near or f"its fields: {', '.join(sorted(node))}"
    return f"--set {item}: the scenario has no field {where} ({hint})"
