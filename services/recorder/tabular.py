"""Flatten bus messages into CSV columns named with units (DESIGN.md §7).

Column names come only from the field metadata of `catabot.bus.messages` (`unit`, `axes`), so
adding a field to a message adds its columns without a second description that could drift.
Numbers are written deterministically (decimal ints, shortest round-trip floats) because the
same scenario and seed must give byte-identical files. A float always reads back as a float:
its text is the shortest that parses back to the very float64 recorded (Ryu, by orjson),
and always has a decimal point or an exponent (`1.0`, `0.1`, `0.00001`, `1e-7`, `1e+16`,
`nan`, `inf`), so pandas and csv readers type a float column float64 even when every value
is whole. One rule for every cell, whether a row comes one sample at a time or a batch's
rows at once (`block_lines`): a body's state reads the same in both.

Layout: `stamp_ns`, `tick`, then every other field in declaration order. A vector field with
axes expands to one column per axis (`position_x[m]`); a variable-length vector (axes None)
to `name_0`, `name_1`, ... for a width taken from the first sample. Bulk NumPy arrays (point
clouds, images) have no tabular form and are left out: they are recorded elsewhere. An array
field whose metadata names a `summary` (column, "len" | "count") gets one column instead: its
length, or its number of non-zero entries (a LiDAR scan's returns and rain returns), so a CSV
of clouds still says per sample how much was seen.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any

import numpy as np
import orjson

from catabot.bus.fields import fields_of
from catabot.bus.messages import Message

LEADING = ("stamp_ns", "tick")


@dataclasses.dataclass(frozen=True)
class _Column:
    """One message field as the CSV sees it: its name, unit and how it expands."""

    name: str
    unit: str
    axes: tuple[str, ...] | None  # None: variable length; () : scalar
    skip: bool = False
    field: str = ""  # the message field, when it differs from the column (a summary)
    reduce: str = ""  # "len" or "count": a bulk array written as one number


def _label(name: str, unit: str) -> str:
    """`surge[m/s]`; a name that already ends in its unit keeps it once (`range_m`)."""
    return f"{name}[{unit}]" if unit and not name.endswith(f"_{unit}") else name


_LAYOUTS: dict[type[Message], tuple[_Column, ...]] = {}


def _layout(cls: type[Message]) -> tuple[_Column, ...]:
    """The fields of `cls` in CSV order, cached because it is needed for every sample.

    (A dict, not functools.cache: mypy rejects classes with dataclass eq as cache keys.)
    """
    found = _LAYOUTS.get(cls)
    if found is None:
        found = _LAYOUTS[cls] = _build_layout(cls)
    return found


def _build_layout(cls: type[Message]) -> tuple[_Column, ...]:
    by_name: dict[str, _Column] = {}
    for f in fields_of(cls):
        if f.kind == "array":
            if f.summary is not None:
                by_name[f.name] = _Column(f.summary[0], "", (), field=f.name, reduce=f.summary[1])
            else:
                by_name[f.name] = _Column(f.name, f.unit, (), skip=True)
        elif f.kind in ("vector", "names"):
            by_name[f.name] = _Column(f.name, f.unit, f.axes)
        else:
            by_name[f.name] = _Column(f.name, f.unit, ())
    first = [by_name.pop(n) for n in LEADING if n in by_name]
    return tuple(c for c in [*first, *by_name.values()] if not c.skip)


def _names(col: _Column, width: int | None) -> list[str]:
    if col.axes is None:
        if width is None:
            raise ValueError(
                f"field {col.name!r} has a variable length: pass width= (from the first sample)"
            )
        return [_label(f"{col.name}_{i}", col.unit) for i in range(width)]
    if not col.axes:
        return [_label(col.name, col.unit)]
    return [_label(f"{col.name}_{axis}", col.unit) for axis in col.axes]


def columns(cls: type[Message], *, width: int | None = None) -> list[str]:
    """Column names of `cls`; `width` sizes every variable-length vector field."""
    return [name for col in _layout(cls) for name in _names(col, width)]


def sample_columns(msg: Message) -> list[str]:
    """Column names sized by one sample: each variable-length field gets its own width."""
    out: list[str] = []
    for col in _layout(type(msg)):
        width = len(getattr(msg, col.name)) if col.axes is None else None
        out.extend(_names(col, width))
    return out


def fmt(value: Any) -> str:
    """One cell, byte-stable across runs: ints in decimal, floats by `float_text`."""
    if isinstance(value, bool | np.bool_):
        return "true" if value else "false"
    if isinstance(value, int | np.integer):
        return str(int(value))
    if isinstance(value, float | np.floating):
        return float_text(value)
    if isinstance(value, str):
        return value
    raise TypeError(f"cannot write a {type(value).__name__} to a CSV cell")


def float_text(value: float | np.floating[Any]) -> str:
    """The shortest text that parses back to `value`, with a point or an exponent (`%.12g`
    wrote 1.0 as `1`, which pandas typed int64, and lost the last digits); JSON has no
    text for the non-finite, so those are Python's (`nan`, `inf`, `-inf`)."""
    number = float(value)  # numpy scalars too: orjson takes a float and nothing else
    return orjson.dumps(number).decode() if math.isfinite(number) else repr(number)


def row(msg: Message) -> list[str]:
    """The cells of one sample, in the order of `columns(type(msg), width=...)`."""
    cells: list[str] = []
    for col in _layout(type(msg)):
        value = getattr(msg, col.field or col.name)
        if col.reduce:
            cells.append(str(len(value) if col.reduce == "len" else np.count_nonzero(value)))
        elif col.axes == ():
            cells.append(fmt(value))
        else:
            cells.extend(fmt(v) for v in value)
    return cells


def block_lines(stamp_ns: int, tick: int, table: np.ndarray) -> list[str]:
    """The CSV lines of N samples sharing a stamp and a tick whose other cells are the float
    columns of `table` (N, C): byte for byte what `row` gives for each (as `fmt` writes
    them)."""
    return _lines(stamp_ns, tick, _tails(table))


def _lines(stamp_ns: int, tick: int, tails: list[str]) -> list[str]:
    head = f"{int(stamp_ns)},{int(tick)},"
    return [head + tail for tail in tails]


def _tails(table: np.ndarray) -> list[str]:
    """Each row's float cells and its line end, as `float_text` writes them: one orjson
    call for the whole (N, C) table, its text cut at the rows. Why: Python's repr, one
    `map(repr)` per row, was the cheapest exact way in Python, and for Table II's 101 rows of
    19 numbers it cost 0.87 ms, orjson 0.04 ms (the recorder's CPU 0.86-0.90 → 0.74-0.77
    ms a tick with 100 boats). orjson writes a non-finite number as `null`, so a row holding
    one is written number by number instead."""
    table = np.ascontiguousarray(table, dtype=np.float64)  # the one layout orjson takes
    if len(table) == 0:
        return []
    text = orjson.dumps(table, option=orjson.OPT_SERIALIZE_NUMPY).decode()
    tails = [cells + "\n" for cells in text[2:-2].split("],[")]
    finite = np.isfinite(table).all(axis=1)
    for i in np.flatnonzero(~finite).tolist():
        tails[i] = ",".join(map(float_text, table[i].tolist())) + "\n"
    return tails


class BlockLines:
    """`block_lines` with a memory: a row bit for bit the same as that row in the last call
    keeps its text. Why: a resting buoy's state does not change (services/physics/sleep.py),
    and formatting the 275 buoys of Table II's waypoint row every tenth tick cost the
    recorder ≈0.25 ms a tick. Bits, not values, decide: -0.0 == 0.0 but prints otherwise."""

    def __init__(self) -> None:
        self._bits: np.ndarray | None = None
        self._tails: list[str] = []

    def __call__(self, stamp_ns: int, tick: int, table: np.ndarray) -> list[str]:
        table = np.ascontiguousarray(table, dtype=np.float64)
        bits = table.view(np.uint64)
        if self._bits is None or self._bits.shape != bits.shape:
            tails = _tails(table)
        else:
            tails = list(self._tails)
            changed = np.flatnonzero((bits != self._bits).any(axis=1))
            for i, tail in zip(changed.tolist(), _tails(table[changed]), strict=True):
                tails[i] = tail
        self._bits, self._tails = bits.copy(), tails
        return _lines(stamp_ns, tick, tails)
