"""CSV columns come from message metadata, with units, and cells are byte-stable."""

from __future__ import annotations

import numpy as np
import pytest

from catabot.bus.messages import Ack, CameraFrame, RadarSweep, ThrustCmd, TwistCmd, VesselState
from services.recorder import tabular


def _state() -> VesselState:
    return VesselState(
        tick=7,
        stamp_ns=700_000_000,
        position=(1.0, -2.5, 0.1),
        orientation=(0.0, 0.0, 0.38268343236508984, 0.9238795325112867),
        linear_velocity=(1.5, 0.0, 0.0),
        angular_velocity=(0.0, 0.0, 0.05),
        linear_acceleration=(0.0, 0.0, 0.0),
        angular_acceleration=(0.0, 0.0, 1e-05),
    )


def test_vessel_state_columns_have_units_and_axes() -> None:
    assert tabular.columns(VesselState) == [
        "stamp_ns",
        "tick",
        "position_x[m]",
        "position_y[m]",
        "position_z[m]",
        "orientation_x",
        "orientation_y",
        "orientation_z",
        "orientation_w",
        "linear_velocity_x[m/s]",
        "linear_velocity_y[m/s]",
        "linear_velocity_z[m/s]",
        "angular_velocity_x[rad/s]",
        "angular_velocity_y[rad/s]",
        "angular_velocity_z[rad/s]",
        "linear_acceleration_x[m/s^2]",
        "linear_acceleration_y[m/s^2]",
        "linear_acceleration_z[m/s^2]",
        "angular_acceleration_x[rad/s^2]",
        "angular_acceleration_y[rad/s^2]",
        "angular_acceleration_z[rad/s^2]",
    ]


def test_variable_length_vector_takes_width() -> None:
    assert tabular.columns(ThrustCmd, width=2) == ["stamp_ns", "tick", "thrust_0", "thrust_1"]
    with pytest.raises(ValueError, match="thrust"):
        tabular.columns(ThrustCmd)


def test_sample_columns_size_by_sample() -> None:
    cmd = ThrustCmd(thrust=(0.5, -0.5, 0.0), tick=3, stamp_ns=300)
    assert tabular.sample_columns(cmd) == tabular.columns(ThrustCmd, width=3)
    assert tabular.row(cmd) == ["300", "3", "0.5", "-0.5", "0.0"]


def test_scalars_with_units() -> None:
    assert tabular.columns(TwistCmd) == ["stamp_ns", "tick", "surge[m/s]", "yaw_rate[rad/s]"]
    assert tabular.row(TwistCmd(surge=2.0, yaw_rate=-0.1, tick=1, stamp_ns=10)) == [
        "10",
        "1",
        "2.0",
        "-0.1",
    ]


def test_row_matches_columns_to_twelve_digits() -> None:
    state = _state()
    cells = tabular.row(state)
    assert len(cells) == len(tabular.columns(VesselState))
    assert cells[:2] == ["700000000", "7"]
    assert cells[-1] == "0.00001"
    assert float(cells[7]) == pytest.approx(state.orientation[2], rel=1e-11)  # 12 digits


def test_message_without_stamp_or_tick_fields() -> None:
    assert tabular.columns(Ack) == ["tick", "run", "end", "fault"]
    assert tabular.row(Ack(run="r1", tick=4)) == ["4", "r1", "", ""]


def test_formatting_is_deterministic_for_numpy_and_specials() -> None:
    assert tabular.fmt(np.float64(0.1)) == "0.1"
    assert tabular.fmt(np.int64(-3)) == "-3"
    assert tabular.fmt(float("nan")) == "nan"
    assert tabular.fmt(float("-inf")) == "-inf"
    assert tabular.fmt(True) == "true"


def test_floats_are_the_shortest_text_that_reads_back_exactly() -> None:
    assert tabular.fmt(1 / 3) == "0.3333333333333333"
    assert tabular.fmt(123456.789012345) == "123456.789012345"
    assert tabular.fmt(1e-7) == "1e-7" and tabular.fmt(2.0) == "2.0"
    assert tabular.fmt(1e16) == "1e+16" and tabular.fmt(1e15) == "1000000000000000.0"


def test_float_text_has_as_few_digits_as_python_repr() -> None:
    """Ryu's text and Python's repr are both the shortest that reads back: the same
    significant digits, whatever the bits (random bit patterns cover subnormals too)."""
    rng = np.random.default_rng(3)
    values = rng.integers(0, 2**64, size=20_000, dtype=np.uint64).view(np.float64)
    for value in values[np.isfinite(values)].tolist():
        text = tabular.float_text(value)
        assert float(text) == value and _digits(text) == _digits(repr(value))


def test_float_text_takes_numpy_scalars_as_floats() -> None:
    assert tabular.float_text(np.float64(0.1)) == "0.1"
    assert tabular.float_text(np.float32(0.5)) == "0.5"
    assert tabular.float_text(np.float64("nan")) == "nan"


def _digits(text: str) -> str:
    return text.split("e")[0].lstrip("-").replace(".", "").strip("0")


def test_block_lines_equal_row_by_row_formatting() -> None:
    """Also where orjson has no text (non-finite numbers): only those rows differ."""
    table = np.array([[0.1, -2.5e-9], [float("nan"), 1e12], [3.0, -float("inf")], [0.0, 1e300]])
    lines = tabular.block_lines(5, 2, table)
    assert lines == [
        "5,2," + ",".join(tabular.fmt(v) for v in row) + "\n" for row in table.tolist()
    ]


def test_remembered_lines_are_the_bytes_of_fresh_ones() -> None:
    """Rows that did not change keep their text, rows that did are formatted again, and
    bits decide (-0.0 after 0.0, a NaN after a NaN)."""
    lines = tabular.BlockLines()
    rng = np.random.default_rng(4)
    table = rng.normal(size=(6, 19))
    table[4, 3], table[5, 0] = 0.0, float("nan")
    for tick in range(4):
        assert lines(10 * tick, tick, table) == tabular.block_lines(10 * tick, tick, table)
        table = table.copy()
        table[tick] = rng.normal(size=19)  # one row moves, the others rest
        table[4, 3] = -table[4, 3]  # 0.0 <-> -0.0: equal values, different text
    assert lines(99, 9, table[:3]) == tabular.block_lines(99, 9, table[:3])  # fewer rows


def test_block_lines_take_any_layout_of_the_table() -> None:
    """orjson reads only C-contiguous float64: a column slice or an int table is made so."""
    table = np.arange(12.0).reshape(3, 4) / 8.0
    assert tabular.block_lines(1, 0, table[:, ::2]) == tabular.block_lines(1, 0, table[:, [0, 2]])
    assert tabular.block_lines(1, 0, np.array([[1, 2]])) == ["1,0,1.0,2.0\n"]


def test_a_name_that_ends_in_its_unit_keeps_it_once() -> None:
    """`range_m[m]` and `hfov_rad[rad]` said the unit twice."""
    assert {"range_m", "heading_rad", "azimuth_start_rad"} <= set(tabular.columns(RadarSweep))
    assert "hfov_rad" in tabular.columns(CameraFrame)
    assert "position_x[m]" in tabular.columns(VesselState)  # a name without it gets it
