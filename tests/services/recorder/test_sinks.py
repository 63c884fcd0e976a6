"""CSV and MCAP sinks: units in headers, byte-identical repeats, kill-safe MCAP."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest
from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory

from catabot.bus.messages import Message, ThrustCmd, TwistCmd, VesselState
from services.recorder.csv_sink import CsvSink, RecorderError
from services.recorder.mcap_read import read_mcap_messages
from services.recorder.mcap_sink import McapSink

STATE = "vessel/ego/state"
THRUST = "vessel/ego/cmd/thrust"
TWIST = "vessel/ego/cmd/twist"
DT = 100_000_000


def _state(tick: int) -> VesselState:
    t = tick * 0.1
    return VesselState(
        tick=tick,
        stamp_ns=tick * DT,
        position=(t, 2.0 * t, 0.0),
        orientation=(0.0, 0.0, 0.1 * t, 1.0),
        linear_velocity=(1.0, 0.0, 0.0),
        angular_velocity=(0.0, 0.0, 0.1),
        linear_acceleration=(0.0, 0.0, 0.0),
        angular_acceleration=(0.0, 0.0, 0.0),
    )


def _samples(ticks: int) -> list[tuple[str, Message]]:
    out: list[tuple[str, Message]] = []
    for k in range(ticks):
        out.append((STATE, _state(k)))
        out.append((THRUST, ThrustCmd(thrust=(0.1 * k, -0.1 * k), tick=k, stamp_ns=k * DT)))
        out.append((TWIST, TwistCmd(surge=1.0 / 3.0, yaw_rate=float("nan"), tick=k, stamp_ns=0)))
    return out


def _record_csv(directory: Path, ticks: int = 5) -> None:
    with CsvSink(directory) as sink:
        for stream, msg in _samples(ticks):
            sink.write(stream, msg)
            sink.flush()


def _record_mcap(path: Path, ticks: int = 5, *, close: bool = True) -> McapSink:
    sink = McapSink(path)
    samples = _samples(ticks)
    for i, (stream, msg) in enumerate(samples):
        sink.write(stream, msg, stamp_ns=(i // 3) * DT)
        if i % 3 == 2:
            sink.flush()
    if close:
        sink.close()
    return sink


def test_csv_files_headers_and_rows(tmp_path: Path) -> None:
    _record_csv(tmp_path, ticks=3)
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        "vessel.ego.cmd.thrust.csv",
        "vessel.ego.cmd.twist.csv",
        "vessel.ego.state.csv",
    ]
    state = (tmp_path / "vessel.ego.state.csv").read_bytes().decode()
    assert state.startswith("stamp_ns,tick,position_x[m],position_y[m],position_z[m],orientation_x")
    assert "\r" not in state and state.endswith("\n")
    assert len(state.splitlines()) == 4
    thrust = (tmp_path / "vessel.ego.cmd.thrust.csv").read_text().splitlines()
    assert thrust[0] == "stamp_ns,tick,thrust_0,thrust_1"
    assert thrust[2] == "100000000,1,0.1,-0.1"
    twist = (tmp_path / "vessel.ego.cmd.twist.csv").read_text().splitlines()
    assert twist[:2] == ["stamp_ns,tick,surge[m/s],yaw_rate[rad/s]", "0,0,0.333333333333,nan"]


def test_csv_is_byte_identical_for_identical_writes(tmp_path: Path) -> None:
    _record_csv(tmp_path / "a")
    _record_csv(tmp_path / "b")
    for f in (tmp_path / "a").iterdir():
        assert f.read_bytes() == (tmp_path / "b" / f.name).read_bytes()


def test_csv_rows_reach_disk_only_on_flush(tmp_path: Path) -> None:
    sink = CsvSink(tmp_path)
    sink.write(STATE, _state(0))
    sink.flush()
    sink.write(STATE, _state(1))  # a kill now must leave exactly the first tick
    lines = (tmp_path / "vessel.ego.state.csv").read_text().splitlines()
    assert len(lines) == 2
    sink.close()
    assert len((tmp_path / "vessel.ego.state.csv").read_text().splitlines()) == 3


def test_csv_width_mismatch_is_refused_without_corrupting(tmp_path: Path) -> None:
    sink = CsvSink(tmp_path)
    sink.write(THRUST, ThrustCmd(thrust=(0.1, 0.2), tick=0, stamp_ns=0))
    with pytest.raises(RecorderError, match=r"vessel/ego/cmd/thrust.*3 columns.*4"):
        sink.write(THRUST, ThrustCmd(thrust=(0.1,), tick=1, stamp_ns=DT))
    with pytest.raises(RecorderError, match="vessel/ego/cmd/thrust"):
        sink.write(THRUST, TwistCmd(surge=1.0, yaw_rate=0.0, tick=1, stamp_ns=DT))
    sink.write(THRUST, ThrustCmd(thrust=(0.3, 0.4), tick=2, stamp_ns=2 * DT))
    sink.close()
    lines = (tmp_path / "vessel.ego.cmd.thrust.csv").read_text().splitlines()
    assert lines == ["stamp_ns,tick,thrust_0,thrust_1", "0,0,0.1,0.2", "200000000,2,0.3,0.4"]
    assert issubclass(RecorderError, ValueError)


def test_mcap_is_byte_identical_for_identical_writes(tmp_path: Path) -> None:
    _record_mcap(tmp_path / "a.mcap")
    _record_mcap(tmp_path / "b.mcap")
    assert (tmp_path / "a.mcap").read_bytes() == (tmp_path / "b.mcap").read_bytes()


def test_mcap_reads_back_with_ros2_and_json(tmp_path: Path) -> None:
    path = tmp_path / "run.mcap"
    _record_mcap(path, ticks=4)
    with open(path, "rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        summary = reader.get_summary()
        assert summary is not None and summary.statistics is not None
        assert summary.statistics.message_count == 12
        assert summary.statistics.message_end_time == 3 * DT
        schemas = {s.name: s.encoding for s in summary.schemas.values()}
        assert schemas == {
            "nav_msgs/msg/Odometry": "ros2msg",
            "catabot.ThrustCmd": "jsonschema",
            "catabot.TwistCmd": "jsonschema",
        }
        for s in summary.schemas.values():
            if s.encoding == "jsonschema":
                assert json.loads(s.data)["type"] == "object"
        for schema, channel, message in reader.iter_messages(log_time_order=False):
            assert message.log_time == message.publish_time
            if channel.message_encoding == "json":
                body = json.loads(message.data)
                assert set(body) >= {"tick", "stamp_ns"}
            else:
                assert schema is not None and channel.topic == "/" + STATE
        f.seek(0)
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        odoms = [m.decoded_message for m in reader.iter_decoded_messages(topics=["/" + STATE])]
    assert len(odoms) == 4
    last = odoms[-1]
    assert last.header.frame_id == "map" and last.child_frame_id == "ego"
    assert (last.header.stamp.sec, last.header.stamp.nanosec) == (0, 3 * DT)
    assert last.pose.pose.position.y == pytest.approx(0.6)
    assert last.twist.twist.angular.z == 0.1


def test_read_helper_on_finished_file(tmp_path: Path) -> None:
    path = tmp_path / "run.mcap"
    _record_mcap(path, ticks=3)
    msgs = read_mcap_messages(path)
    assert [m.topic for m in msgs[:3]] == ["/" + STATE, "/" + THRUST, "/" + TWIST]
    assert len(msgs) == 9
    assert msgs[1].decoded == {"thrust": [0.0, -0.0], "tick": 0, "stamp_ns": 0}
    assert msgs[2].decoded["yaw_rate"] is None  # NaN has no JSON form
    assert msgs[3].decoded.child_frame_id == "ego"
    assert [m.sequence for m in msgs if m.topic == "/" + THRUST] == [0, 1, 2]


def test_truncated_mcap_reads_up_to_last_flush(tmp_path: Path) -> None:
    path = tmp_path / "run.mcap"
    sink = _record_mcap(path, ticks=4, close=False)
    sink.write(STATE, _state(4), stamp_ns=4 * DT)  # written but not flushed: lost on a kill
    killed = tmp_path / "killed.mcap"
    shutil.copyfile(path, killed)  # the bytes a SIGKILL would leave behind
    msgs = read_mcap_messages(killed)
    assert len(msgs) == 12
    assert msgs[-1].log_time == 3 * DT
    assert msgs[-3].decoded.header.stamp.nanosec == 3 * DT
    sink.close()
    assert len(read_mcap_messages(path)) == 13


def test_torn_tail_is_ignored(tmp_path: Path) -> None:
    path = tmp_path / "run.mcap"
    _record_mcap(path, ticks=2, close=False)
    data = path.read_bytes()
    full = len(read_mcap_messages(path))
    for cut in range(len(data) - 1, len(data) - 60, -1):  # a record torn mid-write
        (tmp_path / "torn.mcap").write_bytes(data[:cut])
        assert len(read_mcap_messages(tmp_path / "torn.mcap")) == full - 1
    (tmp_path / "empty.mcap").write_bytes(b"")
    assert read_mcap_messages(tmp_path / "empty.mcap") == []


def test_mcap_refuses_type_change_and_bad_state_stream(tmp_path: Path) -> None:
    with McapSink(tmp_path / "run.mcap") as sink:
        sink.write(THRUST, ThrustCmd(thrust=(0.1,), tick=0, stamp_ns=0), stamp_ns=0)
        with pytest.raises(RecorderError, match="vessel/ego/cmd/thrust"):
            sink.write(THRUST, TwistCmd(surge=1.0, yaw_rate=0.0), stamp_ns=0)
        with pytest.raises(RecorderError, match="vessel/<id>/state"):
            sink.write("env/state", _state(0), stamp_ns=0)


def test_mcap_refuses_malformed_state(tmp_path: Path) -> None:
    bad = VesselState(
        tick=0,
        stamp_ns=0,
        position=(1.0, 2.0),
        orientation=(0.0, 0.0, 0.0, 1.0),
        linear_velocity=(0.0, 0.0, 0.0),
        angular_velocity=(0.0, 0.0, 0.0),
        linear_acceleration=(0.0, 0.0, 0.0),
        angular_acceleration=(0.0, 0.0, 0.0),
    )
    with McapSink(tmp_path / "run.mcap") as sink, pytest.raises(RecorderError, match=STATE):
        sink.write(STATE, bad, stamp_ns=0)
