"""CSV and MCAP sinks: units in headers, byte-identical repeats, kill-safe MCAP that is a ROS 2
bag (profile ros2, CDR only), JSON only in the extras file."""

from __future__ import annotations

import errno
import math
import shutil
from pathlib import Path
from typing import Any

import pytest
import yaml
from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory
from rosbags.highlevel import AnyReader
from rosbags.typesys import Stores, get_typestore

from catabot.bus.messages import Message, ThrustCmd, TwistCmd, VesselState
from catabot.ros2 import cdr, cdr_more, types
from catabot.ros2.convert import thrust
from catabot.ros2.names import TF_STATIC
from catabot.run.mcap_index import McapIndex
from services.recorder.csv_sink import CsvSink, DiskError, RecorderError
from services.recorder.mcap_read import read_mcap_messages
from services.recorder.mcap_sink import McapSink

ROSBAGS = get_typestore(Stores.ROS2_JAZZY)

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


ODOM, TWIST_TOPIC, THRUST_TOPIC = "/ego/odom", "/ego/cmd_vel", "/ego/thrust"
ODOMETRY = cdr.odometry_encoder("map", "ego/base_link")


def _record_mcap(path: Path, ticks: int = 5, *, close: bool = True, **kw: Any) -> McapSink:
    """Per tick an Odometry, a Twist and a thrust array, as the recorder writes them."""
    sink = McapSink(path, **kw)
    for k in range(ticks):
        stamp = k * DT
        sink.write(ODOM, types.ODOMETRY, ODOMETRY(_state(k), stamp), stamp_ns=stamp)
        sink.write(THRUST_TOPIC, types.FLOAT64_ARRAY, thrust((0.1 * k, -0.1 * k)), stamp_ns=stamp)
        sink.write(
            TWIST_TOPIC, types.TWIST, cdr_more.twist(1.0 / 3.0, float("nan")), stamp_ns=stamp
        )
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
    assert twist[:2] == ["stamp_ns,tick,surge[m/s],yaw_rate[rad/s]", "0,0,0.3333333333333333,nan"]


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


def test_mcap_is_a_ros2_bag_that_rosbags_and_mcap_ros2_read(tmp_path: Path) -> None:
    path = tmp_path / "run.mcap"
    _record_mcap(path, ticks=4)
    with open(path, "rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        summary = reader.get_summary()
        assert summary is not None and summary.statistics is not None
        assert reader.get_header().profile == "ros2"
        assert summary.statistics.message_count == 12
        assert summary.statistics.message_end_time == 3 * DT
        assert {s.name: s.encoding for s in summary.schemas.values()} == {
            types.ODOMETRY: "ros2msg",
            types.FLOAT64_ARRAY: "ros2msg",
            types.TWIST: "ros2msg",
        }
        assert {c.message_encoding for c in summary.channels.values()} == {"cdr"}
        odoms = [m.decoded_message for m in reader.iter_decoded_messages(topics=[ODOM])]
    last = odoms[-1]
    assert len(odoms) == 4 and last.child_frame_id == "ego/base_link"
    assert (last.header.stamp.sec, last.header.stamp.nanosec) == (0, 3 * DT)
    assert last.pose.pose.position.y == pytest.approx(0.6) and last.twist.twist.angular.z == 0.1
    with AnyReader([path], default_typestore=ROSBAGS) as bag:
        decoded = [(c.topic, bag.deserialize(raw, c.msgtype)) for c, _, raw in bag.messages()]
    assert len(decoded) == 12
    assert [list(m.data) for t, m in decoded if t == THRUST_TOPIC][1] == [0.1, -0.1]


def test_read_helper_on_finished_file(tmp_path: Path) -> None:
    path = tmp_path / "run.mcap"
    _record_mcap(path, ticks=3)
    msgs = read_mcap_messages(path)
    assert [m.topic for m in msgs[:3]] == [ODOM, THRUST_TOPIC, TWIST_TOPIC]
    assert len(msgs) == 9 and msgs[2].schema_name == types.TWIST
    assert list(msgs[1].decoded.data) == [0.0, -0.0]
    assert math.isnan(msgs[2].decoded.angular.z)  # CDR keeps NaN (JSON had none)
    assert msgs[3].decoded.child_frame_id == "ego/base_link"
    assert [m.sequence for m in msgs if m.topic == THRUST_TOPIC] == [0, 1, 2]


def test_truncated_mcap_reads_up_to_last_flush(tmp_path: Path) -> None:
    path = tmp_path / "run.mcap"
    sink = _record_mcap(path, ticks=4, close=False)
    sink.write(ODOM, types.ODOMETRY, ODOMETRY(_state(4), 4 * DT), stamp_ns=4 * DT)  # not flushed
    killed = tmp_path / "killed.mcap"
    shutil.copyfile(path, killed)  # the bytes a SIGKILL would leave behind
    msgs = read_mcap_messages(killed)
    assert len(msgs) == 12
    assert msgs[-1].log_time == 3 * DT
    assert msgs[-3].decoded.header.stamp.nanosec == 3 * DT
    sink.close()
    assert len(read_mcap_messages(path)) == 13


def test_torn_tail_is_ignored(tmp_path: Path) -> None:
    """A torn chunk is lost whole; what came before it reads (here a chunk a log time: the
    messages of one time share a chunk, however they came in blocks)."""
    path = tmp_path / "run.mcap"
    _record_mcap(path, ticks=2, close=False, chunk_bytes=1)
    data = path.read_bytes()
    messages = read_mcap_messages(path)
    last = [m for m in messages if m.log_time == messages[-1].log_time]
    assert 0 < len(last) < len(messages)
    for cut in range(len(data) - 1, len(data) - 60, -1):  # a record torn mid-write
        (tmp_path / "torn.mcap").write_bytes(data[:cut])
        assert len(read_mcap_messages(tmp_path / "torn.mcap")) == len(messages) - len(last)
    (tmp_path / "empty.mcap").write_bytes(b"")
    assert read_mcap_messages(tmp_path / "empty.mcap") == []


def test_mcap_refuses_a_type_change_json_and_writes_after_close(tmp_path: Path) -> None:
    sink = McapSink(tmp_path / "run.mcap")
    sink.write(THRUST_TOPIC, types.FLOAT64_ARRAY, thrust((0.1,)), stamp_ns=0)
    with pytest.raises(RecorderError, match="a geometry_msgs/msg/Twist on a channel of std_msgs"):
        sink.write(THRUST_TOPIC, types.TWIST, cdr_more.twist(1.0, 0.0), stamp_ns=0)
    with pytest.raises(RecorderError, match="JSON has no place in a ros2 MCAP"):
        sink.write_json("/x", "s", {}, b"{}", stamp_ns=0)
    sink.close()
    with pytest.raises(RecorderError, match="closed"):
        sink.write(THRUST_TOPIC, types.FLOAT64_ARRAY, thrust((0.1,)), stamp_ns=0)


def test_extras_are_json_with_a_schema(tmp_path: Path) -> None:
    schema = {"title": "catabot.Note", "type": "object"}
    with McapSink(tmp_path / "run.extra.mcap", profile="") as sink:
        sink.write_json("/ego/cam/labels", "catabot.Note", schema, b'{"a":1}', stamp_ns=5)
        with pytest.raises(RecorderError, match=r"CDR belongs in run\.mcap"):
            sink.write(ODOM, types.ODOMETRY, ODOMETRY(_state(0), 0), stamp_ns=0)
    (msg,) = read_mcap_messages(tmp_path / "run.extra.mcap")
    assert (msg.topic, msg.schema_name, msg.decoded, msg.log_time) == (
        "/ego/cam/labels",
        "catabot.Note",
        {"a": 1},
        5,
    )


class _FullDisk:
    """A file with `room` bytes left: a write past it writes what fits, then fails."""

    def __init__(self, file: Any, room: int) -> None:
        self._file, self._room = file, room

    def write(self, data: Any) -> int:
        if self._room <= 0:
            raise OSError(errno.ENOSPC, "No space left on device")
        written = int(self._file.write(data[: self._room]))
        self._room -= written
        return written

    def __getattr__(self, name: str) -> Any:
        return getattr(self._file, name)


def test_a_full_disk_cuts_the_mcap_back_to_its_last_whole_chunk(tmp_path: Path) -> None:
    """A failed flush is cut back off: the file ends with the last finished chunk."""
    path = tmp_path / "run.mcap"
    sink = _record_mcap(path, ticks=6, close=False, chunk_bytes=1500)  # chunks of ~5 messages
    finished = [m.log_time for m in read_mcap_messages(path)]
    sink.write(ODOM, types.ODOMETRY, ODOMETRY(_state(6), 6 * DT), stamp_ns=6 * DT)
    sink._out._file = _FullDisk(sink._out._file, room=100)  # type: ignore[assignment]
    with pytest.raises(DiskError, match="No space left on device"):
        sink.flush()
    left = read_mcap_messages(path)
    assert 0 < len(left) < len(finished)  # the finished chunks, not the open one
    assert path.stat().st_size == sink._out._size  # cut back to the last whole chunk
    assert [m.log_time for m in left] == finished[: len(left)]
    assert McapIndex(path).channel(ODOM) is not None


def test_each_channel_offers_the_gateways_qos_as_every_rosbag2_reads_them(
    tmp_path: Path,
) -> None:
    """Humble's integers, and a `rosbag2` record without serialized metadata, which Jazzy
    and later take for a version-8 bag (integers): `ros2 bag play` then offers /tf_static
    TRANSIENT_LOCAL, as the gateway does, so latched subscribers (RViz's) get it."""
    path = tmp_path / "run.mcap"
    sink = _record_mcap(path, ticks=1, close=False)
    sink.write(TF_STATIC, types.TF, b"\x00\x01\x00\x00" + bytes(4), stamp_ns=0)
    sink.close()
    with open(path, "rb") as f:
        reader = make_reader(f, validate_crcs=True)
        channels = {c.topic: c.metadata for c in reader.get_summary().channels.values()}  # type: ignore[union-attr]
        records = [(m.name, m.metadata) for m in reader.iter_metadata()]
    latched = yaml.safe_load(channels[TF_STATIC]["offered_qos_profiles"])
    data = yaml.safe_load(channels[ODOM]["offered_qos_profiles"])
    assert latched == [{
        "history": 1, "depth": 1, "reliability": 1, "durability": 1,
        "deadline": {"sec": 0, "nsec": 0}, "lifespan": {"sec": 0, "nsec": 0},
        "liveliness": 1, "liveliness_lease_duration": {"sec": 0, "nsec": 0},
        "avoid_ros_namespace_conventions": False,
    }]  # fmt: skip
    assert (data[0]["durability"], data[0]["depth"], data[0]["reliability"]) == (2, 10, 1)
    assert records == [("rosbag2", {"ROS_DISTRO": "humble"})]
    with AnyReader([path], default_typestore=ROSBAGS) as bag:
        assert {c.topic for c in bag.connections} >= {ODOM, TF_STATIC}
    extra = McapSink(tmp_path / "run.extra.mcap", profile="")
    extra.write_json("/labels", "catabot/Labels", {"type": "object"}, b"{}", stamp_ns=0)
    extra.close()
    with open(tmp_path / "run.extra.mcap", "rb") as f:
        reader = make_reader(f)
        assert [c.metadata for c in reader.get_summary().channels.values()] == [{}]  # type: ignore[union-attr]
        assert list(reader.iter_metadata()) == []
