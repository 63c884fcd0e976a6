"""Batches are recorded as the per-vessel streams they stand for, byte for byte."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from catabot.bus.messages import BodyStates, TwistBatch, TwistCmd, VesselState
from catabot.config.base import ConfigError
from catabot.config.load import parse_scenario
from catabot.ros2 import cdr, cdr_more, types
from catabot.ros2.convert import Converter
from catabot.world.world import World
from services.recorder.batches import BatchFormatter, Block
from services.recorder.csv_sink import CsvSink, RecorderError
from services.recorder.mcap_read import read_mcap_messages
from services.recorder.mcap_sink import McapSink

SCENARIO = {"name": "b", "vessels": [{"id": "ego"}], "traffic": {"count": 1},
            "buoys": [{"id": "buoy_0", "x_m": 50.0, "y_m": 0.0}],
            "recording": {"traffic_rate_hz": None}}  # fmt: skip
WORLD = World.resolve(parse_scenario(SCENARIO))  # every body every tick
IDS = ("ego", "boat_000", "buoy_0")
BOATS = ("boat_000",)
assert WORLD.body_ids == IDS and WORLD.boat_ids == BOATS


def _formatter() -> BatchFormatter:
    return BatchFormatter(Converter(WORLD))


def _states(tick: int) -> BodyStates:
    rng = np.random.default_rng(tick)
    n = len(IDS)
    arrays = [rng.normal(size=(n, 3)), rng.normal(size=(n, 4))]
    arrays += [rng.normal(size=(n, 3)) * 1e-7 for _ in range(4)]  # small: exponents in repr
    return BodyStates(tick, (tick + 1) * 10_000_000, IDS, *arrays)


def _twists(tick: int, surge: float = 1.5) -> TwistBatch:
    return TwistBatch(tick, tick * 10_000_000, BOATS, np.array([surge]), np.array([-0.1]))


def _csv_by_message(tmp: Path, stream: str, msgs: list[VesselState] | list[TwistCmd]) -> str:
    with CsvSink(tmp) as sink:
        for msg in msgs:
            sink.write(stream, msg)
    return (tmp / (stream.replace("/", ".") + ".csv")).read_text()


def test_states_block_equals_the_per_message_rows(tmp_path: Path) -> None:
    fmt = _formatter()
    batches = [_states(k) for k in range(3)]
    with CsvSink(tmp_path / "block") as sink:
        for batch in batches:
            block = fmt.states(batch)
            sink.write_lines(block.streams, block.cls, block.lines)
    for i, vid in enumerate(IDS):
        rows = [b.row(i) for b in batches]
        expected = _csv_by_message(tmp_path / vid, f"vessel/{vid}/state", rows)
        assert (tmp_path / "block" / f"vessel.{vid}.state.csv").read_text() == expected
        odometry = cdr.odometry_encoder("map", f"{vid}/base_link")
        payload = _payloads(fmt.states(batches[2])).get(i)
        assert payload == (odometry(rows[2], batches[2].stamp_ns) if i < 2 else None)  # buoy: /tf
    frames = [f"{b}/base_link" for b in IDS]
    tf = cdr.TfBatch("map", frames).encode(
        batches[2].stamp_ns, batches[2].position, batches[2].orientation
    )
    assert fmt.states(batches[2]).tf == tf
    assert fmt.states(batches[2]).topics == ("/ego/odom", "/boat_000/odom")


def test_traffic_and_buoys_are_recorded_at_their_rate_the_vessels_every_tick(
    tmp_path: Path,
) -> None:
    thinned = World.resolve(parse_scenario({**SCENARIO, "recording": {"traffic_rate_hz": 10}}))
    fmt = BatchFormatter(Converter(thinned))
    batches = [_states(k) for k in range(21)]
    with CsvSink(tmp_path / "block") as sink:
        for batch in batches:
            block = fmt.states(batch)
            sink.write_lines(block.streams, block.cls, block.lines)
    for i, vid in enumerate(IDS):
        ticks = range(21) if vid == "ego" else (9, 19)  # stamped 0.1, 0.2 s (the start: -1)
        expected = _csv_by_message(tmp_path / vid, f"vessel/{vid}/state",
                                   [batches[k].row(i) for k in ticks])  # fmt: skip
        assert (tmp_path / "block" / f"vessel.{vid}.state.csv").read_text() == expected
    assert fmt.thin.every_body(-1) and not fmt.thin.every_body(0)  # the start, not 0.01 s
    between = fmt.states(batches[7])  # the ego alone: its Odometry and its frame on /tf
    assert between.topics == ("/ego/odom",)
    odometry = cdr.odometry_encoder("map", "ego/base_link")
    assert _payloads(between) == {0: odometry(batches[7].row(0), batches[7].stamp_ns)}
    tf = cdr.TfBatch("map", ["ego/base_link"])
    assert between.tf == tf.encode(batches[7].stamp_ns, batches[7].position[:1],
                                   batches[7].orientation[:1])  # fmt: skip
    with pytest.raises(ValueError, match="boat_000"):  # rows still checked between samples
        fmt.states(BodyStates(7, 0, ("ego", "buoy_0", "boat_000"), *batches[7].arrays()))


def test_a_traffic_rate_that_is_not_whole_ticks_is_refused() -> None:
    with pytest.raises(ConfigError, match=r"recording.traffic_rate_hz.*null records every"):
        World.resolve(parse_scenario({**SCENARIO, "recording": {"traffic_rate_hz": 30}}))


def _payloads(block: Block) -> dict[int, bytes]:
    """Row -> payload, from the block's byte-matrix groups."""
    return {
        i: bytes(matrix[j]) for rows, matrix in block.groups for j, i in enumerate(rows.tolist())
    }


def test_twist_block_equals_the_per_message_csv_and_twist(tmp_path: Path) -> None:
    fmt = _formatter()
    block = fmt.twists(_twists(4))
    msg = TwistCmd(1.5, -0.1, 4, 40_000_000)
    assert block.streams == ("vessel/boat_000/cmd/twist",)
    assert block.topics == ("/boat_000/cmd_vel",) and block.typename == types.TWIST
    assert _payloads(block) == {0: cdr_more.twist(1.5, -0.1)}
    with CsvSink(tmp_path / "block") as sink:
        sink.write_lines(block.streams, block.cls, block.lines)
    expected = _csv_by_message(tmp_path / "one", "vessel/boat_000/cmd/twist", [msg])
    assert (tmp_path / "block" / "vessel.boat_000.cmd.twist.csv").read_text() == expected


def test_non_finite_set_point_is_recorded_as_it_is() -> None:
    block = _formatter().twists(_twists(1, surge=float("nan")))
    assert _payloads(block) == {0: cdr_more.twist(float("nan"), -0.1)}  # CDR has NaN
    assert block.lines[0].split(",")[2] == "nan"


def test_batches_of_other_vessels_are_refused() -> None:
    fmt = _formatter()
    moved = _states(0)
    other = BodyStates(0, 0, ("a", "b", "c"), *moved.arrays())
    with pytest.raises(ValueError, match="expected"):
        fmt.states(other)
    with pytest.raises(ValueError, match="expected"):
        fmt.twists(TwistBatch(0, 0, ("x",), np.zeros(1), np.zeros(1)))
    with pytest.raises(ValueError, match=r"surge is \(2,\), not \(1,\)"):
        fmt.twists(TwistBatch(0, 0, BOATS, np.zeros(2), np.zeros(1)))


def test_block_on_a_stream_of_another_type_is_refused(tmp_path: Path) -> None:
    with CsvSink(tmp_path) as sink:
        sink.write("vessel/ego/state", _states(0).row(0))
        with pytest.raises(RecorderError, match="TwistCmd sample on a stream of VesselState"):
            sink.write_lines(["vessel/ego/state"], TwistCmd, ["1,0,1.0,2.0\n"])
        with pytest.raises(RecorderError, match="2 lines for 1 streams"):
            sink.write_lines(["vessel/ego/state"], VesselState, ["a\n", "b\n"])


def test_mcap_blocks_read_back_as_odometry_and_refuse_another_type(tmp_path: Path) -> None:
    fmt = _formatter()
    with McapSink(tmp_path / "run.mcap") as sink:
        for tick in range(2):
            block = fmt.states(_states(tick))
            for rows, matrix in block.groups:
                topics = [block.topics[i] for i in rows.tolist()]
                sink.write_matrix(topics, block.typename, matrix, stamp_ns=block.stamp_ns)
        with pytest.raises(RecorderError, match="a geometry_msgs/msg/Twist on a channel of nav"):
            sink.write_matrix(topics, types.TWIST, matrix, stamp_ns=0)
        with pytest.raises(RecorderError, match="appears twice"):
            sink.write_matrix([topics[0], topics[0]], types.ODOMETRY, matrix, stamp_ns=0)
    msgs = read_mcap_messages(tmp_path / "run.mcap")
    assert len(msgs) == 2 * 2  # two vessels (the buoy has no Odometry channel)
    ego = [m for m in msgs if m.topic == "/ego/odom"]
    assert [m.sequence for m in ego] == [0, 1]
    assert ego[1].decoded.pose.pose.position.x == _states(1).position[0, 0]
