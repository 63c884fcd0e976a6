"""Every float field of every recorded message reads back as float64 with pandas, whole
values included (`%.12g` wrote 1.0 as `1`, which pandas typed int64), and every value is
the very float64 recorded."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import pytest

from catabot.bus.fields import FieldSpec, fields_of
from catabot.bus.messages import (
    GpsFix,
    ImuSample,
    Message,
    RadarSweep,
    ThrustCmd,
    TwistCmd,
    VesselState,
    WaypointsCmd,
)
from services.recorder import tabular
from services.recorder.csv_sink import CsvSink

# the recorded messages with float fields (LidarScan's row has counts, SettingsChange text)
RECORDED = [VesselState, ThrustCmd, TwistCmd, WaypointsCmd, ImuSample, GpsFix, RadarSweep]


def _value(spec: FieldSpec, k: int) -> Any:
    """A whole-valued sample value of the field's kind (the case that lost its `.0`)."""
    if spec.kind == "float":
        return float(k)
    if spec.kind == "vector":
        return tuple(float(k + i) for i in range(len(spec.axes) if spec.axes else 2))
    if spec.kind == "array":
        return np.zeros(3, np.float32)
    if spec.kind == "names":
        return ("a",)
    return {"int": k, "bool": True, "str": "on"}[spec.kind]


def _integer_columns(cls: type[Message]) -> set[str]:
    out = set()
    for spec in fields_of(cls):
        if spec.kind in ("int", "bool", "str"):
            out.add(f"{spec.name}[{spec.unit}]" if spec.unit else spec.name)
        elif spec.kind == "array" and spec.summary is not None:
            out.add(spec.summary[0])
    return out


@pytest.mark.parametrize("cls", RECORDED, ids=lambda c: c.__name__)
def test_pandas_reads_every_float_field_as_float(tmp_path: Path, cls: type[Message]) -> None:
    with CsvSink(tmp_path) as sink:
        for k in range(3):
            sink.write("s", cls(**{f.name: _value(f, k) for f in fields_of(cls)}))
    frame = pd.read_csv(tmp_path / "s.csv")
    ints = _integer_columns(cls)
    floats = [c for c in frame.columns if c not in ints]
    assert floats, f"{cls.__name__}: no float column"
    assert {c: str(frame[c].dtype) for c in floats} == dict.fromkeys(floats, "float64")
    assert frame[floats[0]].tolist()[:2] == [0.0, 1.0]
    assert not any(frame[c].dtype == np.float64 for c in ints if c in frame)


def test_the_batch_path_keeps_floats_too(tmp_path: Path) -> None:
    table = np.array([[1.0, -0.0, 2.0], [3.0, 1e20, 5.0]])
    lines = tabular.block_lines(10, 1, table)
    assert lines == ["10,1,1.0,-0.0,2.0\n", "10,1,3.0,1e+20,5.0\n"]
    (tmp_path / "b.csv").write_text("stamp_ns,tick,a,b,c\n" + "".join(lines))
    frame = pd.read_csv(tmp_path / "b.csv")
    assert [str(t) for t in frame.dtypes] == ["int64", "int64", "float64", "float64", "float64"]


def test_every_float_round_trips_exactly_and_specials_read_as_such() -> None:
    rng = np.random.default_rng(7)
    values = np.concatenate([
        rng.normal(size=2000) * 10.0 ** rng.integers(-12, 12, 2000),
        [0.1, 1 / 3, 1e-5, 2.0**-1074, 1.7976931348623157e308, -0.0, 123456.789012345],
    ])  # fmt: skip
    text = tabular.block_lines(0, 0, values.reshape(1, -1))[0].rstrip("\n").split(",")[2:]
    assert [float(t) for t in text] == values.tolist()
    assert all("." in t or "e" in t for t in text)  # a float's text, never an int's
    assert tabular.fmt(1e-05) == "0.00001" and tabular.fmt(np.float64(1.0)) == "1.0"
    specials = tabular.block_lines(0, 0, np.array([[math.nan, math.inf, -math.inf]]))
    assert specials == ["0,0,nan,inf,-inf\n"]
