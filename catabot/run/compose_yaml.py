"""A compose document as YAML text, with comments, byte for byte the same every time.

The document is plain data (dicts, lists, strings, ints, bools); lists of scalars and the
small maps inside lists are written in flow style, strings quoted whenever YAML could read
them as anything else. A JSON string is a valid YAML double-quoted scalar, so quoting is
`json.dumps`. No YAML library is needed at run time (pyyaml only checks it, in the tests).
"""

from __future__ import annotations

import json
import re
from collections.abc import Mapping

Data = object
PLAIN = re.compile(r"^(--?)?[A-Za-z_/][A-Za-z0-9_./-]*$")
SPECIAL = {"true", "false", "yes", "no", "on", "off", "null", "y", "n", "~"}
WIDTH = 99


def scalar(value: Data) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, str):
        plain = PLAIN.match(value) and value.lower() not in SPECIAL
        return value if plain else json.dumps(value)
    raise TypeError(f"compose YAML: cannot write {type(value).__name__} {value!r}")


def flow(value: Data) -> str:
    """A list or a map on one line: `[a, "b c"]`, `{source: x, target: y}`."""
    if isinstance(value, Mapping):
        return "{" + ", ".join(f"{scalar(k)}: {flow(v)}" for k, v in value.items()) + "}"
    if isinstance(value, list):
        return "[" + ", ".join(flow(v) for v in value) + "]"
    return scalar(value)


def _flat(value: Data) -> bool:
    """A value written on its key's line: a scalar, or a list of scalars and flat maps."""
    if isinstance(value, list):
        return all(not isinstance(v, list | Mapping) or _flat_map(v) for v in value)
    return not isinstance(value, Mapping)


def _flat_map(value: Data) -> bool:
    return isinstance(value, Mapping) and not any(
        isinstance(v, list | Mapping) for v in value.values()
    )


def block(
    data: Mapping[str, Data], notes: Mapping[str, str], path: str = "", indent: int = 0
) -> list[str]:
    """The lines of a block map; `notes[path]` is a comment above the key at `path`
    (dotted: `services.traffic`)."""
    lines: list[str] = []
    pad = " " * indent
    for key, value in data.items():
        here = f"{path}.{key}" if path else key
        lines += [f"{pad}# {line}".rstrip() for line in notes.get(here, "").splitlines()]
        if isinstance(value, Mapping) and value:
            lines.append(f"{pad}{scalar(key)}:")
            lines += block(value, notes, here, indent + 2)
        elif _flat(value) or value == {}:
            lines += _keyed(pad, key, value)
        else:
            raise TypeError(f"compose YAML: {here} nests lists; use a map")
    return lines


def _keyed(pad: str, key: str, value: Data) -> list[str]:
    """`key: value`, a long flow list wrapped one item a line."""
    line = f"{pad}{scalar(key)}: {flow(value)}"
    if len(line) <= WIDTH or not isinstance(value, list):
        return [line]
    items = [f"{pad}  - {flow(v)}" for v in value]
    return [f"{pad}{scalar(key)}:", *items]


def dump(data: Mapping[str, Data], notes: Mapping[str, str], header: str) -> str:
    """The whole file: the header as comment lines, then the document."""
    head = [f"# {line}".rstrip() for line in header.splitlines()]
    return "\n".join([*head, *block(data, notes)]) + "\n"
