"""The ROS 2 gateway through `catabot run`, seen by a ROS 2 stack on Zenoh in both conventions
(tests/e2e/ros_client.py: rosbags for payloads, keys spelled from the conventions):
every topic decodes into the right type with the right values, rmw_zenoh attachments and
graph tokens parse, and Twists on `cmd_vel` drive the vessels; malformed ones are ignored."""

from __future__ import annotations

import csv
import re
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from conftest import only_run_dir, scenario_file, start
from ros_client import (
    ROSBAGS,
    RosClient,
    Sample,
    bridge_key,
    decode,
    rmw_key,
    stamp_ns,
    twist,
)

from catabot.bus.session import free_port
from catabot.world import rotations
from services.recorder.mcap_read import read_mcap_messages

DT = 10_000_000
SENSORS = [
    {"name": "imu", "type": "imu", "rate_hz": 100.0},
    {"name": "gps", "type": "gps", "rate_hz": 10.0},
    {"name": "lidar", "type": "lidar", "rate_hz": 10.0},
    {"name": "radar", "type": "radar", "rate_hz": 20.0, "params": {"rotation_period_s": 0.5}},
    {"name": "cam", "type": "camera", "rate_hz": 5.0, "params": {"width": 80, "height": 60}},
]
TOPICS = {
    "/ego/odom": "nav_msgs/msg/Odometry",
    "/other/odom": "nav_msgs/msg/Odometry",
    "/boat_000/odom": "nav_msgs/msg/Odometry",
    "/tf": "tf2_msgs/msg/TFMessage",
    "/tf_static": "tf2_msgs/msg/TFMessage",
    "/clock": "rosgraph_msgs/msg/Clock",
    "/buoys": "visualization_msgs/msg/MarkerArray",
    "/ego/imu/imu": "sensor_msgs/msg/Imu",
    "/ego/gps/fix": "sensor_msgs/msg/NavSatFix",
    "/ego/lidar/points": "sensor_msgs/msg/PointCloud2",
    "/ego/radar/points": "sensor_msgs/msg/PointCloud2",
    "/ego/radar/ppi": "sensor_msgs/msg/Image",
    **{f"/ego/cam/{name}": "sensor_msgs/msg/Image"
       for name in ("image_raw", "depth", "segmentation", "instance", "normals")},
    "/ego/cam/camera_info": "sensor_msgs/msg/CameraInfo",
}  # fmt: skip
ENCODINGS = {"image_raw": "rgb8", "depth": "32FC1", "segmentation": "mono8",
             "instance": "mono16", "normals": "rgb8"}  # fmt: skip
LATCHED = ("/tf_static", "/buoys")  # sent once; TRANSIENT_LOCAL subscribers get them late
COMMANDED = {"ego": 1.0, "other": 1.5}  # surge set-points: ego by bridge, other by rmw_zenoh


def _scenario() -> dict[str, Any]:
    return {
        "name": "rosgw",
        "seed": 4,
        "duration_s": 9.0,
        "clock": {"realtime_factor": 1.5},
        "origin": {"latitude_deg": 43.7, "longitude_deg": -72.3},
        "vessels": [
            {"id": "ego", "pose": {"x_m": 0.0, "y_m": 0.0}, "sensors": SENSORS},
            {"id": "other", "model": "wamv", "pose": {"x_m": 0.0, "y_m": 40.0}},
        ],
        "buoys": [{"id": "b1", "x_m": 9.0, "y_m": 0.0}],
        "traffic": {"count": 1, "region": {"center_m": [-200.0, -200.0], "size_m": [100, 100]}},
        "ros": {"mode": "both"},
        "recording": {"traffic_rate_hz": None},  # every body every tick, as the gateway sends
    }  # fmt: skip


@dataclass
class Live:
    run: Path
    returncode: int
    got: dict[tuple[str, str], list[Sample]]  # (topic, "bridge" | "rmw") -> samples
    rmw_tokens: list[str]
    bridge_tokens: list[str]


def _drive(client: RosClient, garbage: bool) -> None:
    """What a stack would send: the set-points, and (for a second) junk on the same topics."""
    client.put(bridge_key("/ego/cmd_vel"), twist(COMMANDED["ego"], 0.0))
    other = rmw_key("/other/cmd_vel", "geometry_msgs/msg/Twist")
    client.put(other, twist(COMMANDED["other"], 0.0), rmw=True)
    if garbage:
        client.put(bridge_key("/ego/cmd_vel"), b"not cdr at all")
        string = ROSBAGS.types["std_msgs/msg/String"](data="hello")
        client.put(other, bytes(ROSBAGS.serialize_cdr(string, "std_msgs/msg/String")), rmw=True)


@pytest.fixture(scope="module")
def live(tmp_path_factory: pytest.TempPathFactory) -> Live:
    tmp = tmp_path_factory.mktemp("gateway")
    out = tmp / "runs"
    out.mkdir()
    endpoint = f"tcp/127.0.0.1:{free_port()}"
    client = RosClient(endpoint)
    got = {}
    for topic, typename in TOPICS.items():
        latched = topic in LATCHED
        got[(topic, "bridge")] = client.subscribe(bridge_key(topic), transient_local=latched)
        got[(topic, "rmw")] = client.subscribe(rmw_key(topic, typename), transient_local=latched)
    proc = start("run", str(scenario_file(tmp, _scenario())), "--out", str(out), "--quiet",
                 "--listen", endpoint)  # fmt: skip
    tokens: tuple[list[str], list[str]] = ([], [])
    first_odom = 0.0
    try:
        while proc.poll() is None:
            odom = got[("/ego/odom", "bridge")]
            if odom and not first_odom:
                first_odom = time.monotonic()
                tokens = (client.tokens("@ros2_lv/0/**"), client.tokens("@/*/@ros2_lv/**"))
            garbage = bool(first_odom) and time.monotonic() - first_odom < 1.0
            _drive(client, garbage)
            time.sleep(0.05)
        _, err = proc.communicate(timeout=60)
    finally:
        client.close()
    assert list(out.iterdir()), err
    return Live(only_run_dir(out), proc.returncode, got, *tokens)


def _recorded(run: Path) -> dict[tuple[str, int], bytes]:
    """(topic, header stamp or log time) -> payload of every message of run.mcap."""
    return {(m.topic, m.log_time): m.data for m in read_mcap_messages(run / "run.mcap")}


def test_the_run_completes(live: Live) -> None:
    assert live.returncode == 0, (live.run / "log" / "ros.log").read_text()[-2000:]


@pytest.mark.parametrize("convention", ["bridge", "rmw"])
def test_every_topic_decodes_as_its_type_and_equals_the_recording(
    live: Live, convention: str
) -> None:
    recorded = _recorded(live.run)
    first_sweep = stamp_ns(decode(live.got[("/ego/radar/points", convention)][0].payload,
                                  TOPICS["/ego/radar/points"]).header)  # fmt: skip
    for topic, typename in TOPICS.items():
        samples = live.got[(topic, convention)]
        assert samples, f"nothing on {topic} ({convention})"
        for sample in samples:
            msg = decode(sample.payload, typename)
            if topic == "/clock":
                continue
            stamp = stamp_ns(_header(topic, msg))
            assert stamp % DT == 0, f"{topic}: stamp {stamp} is not a tick's"
            if topic == "/ego/radar/ppi" and stamp < first_sweep + 1_500_000_000:
                continue  # a PPI shows the last second of sweeps: it is whole 1 s after the first
            assert recorded[(topic, stamp)] == sample.payload, f"{topic} at {stamp}"


def _header(topic: str, msg: Any) -> Any:
    if topic.startswith("/tf"):
        return msg.transforms[0].header
    return msg.markers[0].header if topic == "/buoys" else msg.header


def test_rmw_zenoh_keys_carry_the_type_and_hash(live: Live) -> None:
    for topic, typename in TOPICS.items():
        (key,) = {s.key for s in live.got[(topic, "rmw")]}
        pkg, _, name = typename.split("/")
        assert (
            key == f"0/{topic.strip('/')}/{pkg}::msg::dds_::{name}_/{ROSBAGS.hash_rihs01(typename)}"
        )


def test_attachments_parse_with_increasing_sequence_and_stable_gid(live: Live) -> None:
    gids = set()
    for topic in TOPICS:
        samples = live.got[(topic, "rmw")]
        parsed = []
        for s in samples:
            assert s.attachment is not None and len(s.attachment) == 33 and s.attachment[16] == 16
            seq, ts = np.frombuffer(s.attachment[:16], "<i8").tolist()
            parsed.append((seq, ts, s.attachment[17:]))
            assert abs(ts / 1e9 - s.at) < 5.0  # a source timestamp, as rmw_zenoh sets
        seqs = [p[0] for p in parsed]  # gaps are samples Zenoh dropped (puts never block)
        assert seqs[0] >= 1 and all(np.diff(seqs) > 0), topic
        assert len({p[2] for p in parsed}) == 1
        gids.add(parsed[0][2])
        assert all(s.attachment is None for s in live.got[(topic, "bridge")])
    assert len(gids) == len(TOPICS)  # one publisher each


_RMW_TOKEN = re.compile(
    r"^@ros2_lv/(?P<domain>\d+)/(?P<zid>[0-9a-f]+)/(?P<nid>\d+)/(?P<eid>\d+)/(?P<kind>NN|MP|MS)"
    r"/(?P<enclave>[^/]+)/(?P<ns>[^/]+)/(?P<node>[^/]+)"
    r"(/(?P<topic>[^/]+)/(?P<type>[^/]+)/(?P<hash>RIHS01_[0-9a-f]{64})/(?P<qos>[^/]+))?$"
)


def test_rmw_graph_tokens_show_a_catabot_node_and_its_topics(live: Live) -> None:
    parsed = [_RMW_TOKEN.match(t) for t in live.rmw_tokens]
    assert all(parsed), [t for t, m in zip(live.rmw_tokens, parsed, strict=True) if not m]
    nodes = [m for m in parsed if m and m["kind"] == "NN"]
    assert [(n["domain"], n["ns"], n["node"]) for n in nodes] == [("0", "%", "catabot")]
    entities = {(m["kind"], m["topic"].replace("%", "/")): m for m in parsed if m and m["topic"]}
    odom = entities[("MP", "/ego/odom")]
    assert odom["type"] == "nav_msgs::msg::dds_::Odometry_"
    assert odom["hash"] == ROSBAGS.hash_rihs01("nav_msgs/msg/Odometry")
    reliability, durability, history = odom["qos"].split(":")[:3]
    assert (reliability, durability, history) == ("", "", ",10")  # reliable, volatile, depth 10
    assert entities[("MP", "/tf_static")]["qos"].split(":")[1] == "1"  # transient local
    assert entities[("MS", "/ego/cmd_vel")]["type"] == "geometry_msgs::msg::dds_::Twist_"
    assert {("MS", f"/{v}/{c}") for v in ("ego", "other", "boat_000")
            for c in ("cmd_vel", "thrust", "waypoints")} <= set(entities)  # fmt: skip
    assert len({m["eid"] for m in parsed if m}) == len(parsed)  # one id per entity


def test_bridge_route_tokens_announce_every_topic(live: Live) -> None:
    routes = {}
    for token in live.bridge_tokens:
        head, kind, key, typename, qos = token.split("/", 2)[-1].split("/")
        assert head == "@ros2_lv"
        routes[(kind, key.replace("§", "/"))] = (typename.replace("§", "/"), qos)
    for topic, typename in TOPICS.items():
        got_type, qos = routes[("MP", topic.strip("/"))]
        keyless, reliability, durability, history, user = qos.split(":")
        assert (got_type, keyless, reliability, history) == (typename, "", "1", "0,1" if
                topic in LATCHED else "0,10")  # fmt: skip
        assert durability == ("1" if topic in LATCHED else "0")
        assert user == f"typehash={ROSBAGS.hash_rihs01(typename)};"
    assert routes[("MS", "ego/cmd_vel")][0] == "geometry_msgs/msg/Twist"


def _by(live: Live, topic: str) -> list[Any]:
    return [decode(s.payload, TOPICS[topic]) for s in live.got[(topic, "bridge")]]


def test_clock_advances_tick_by_tick(live: Live) -> None:
    clock = [int(c.clock.sec) * 10**9 + int(c.clock.nanosec) for c in _by(live, "/clock")]
    steps = np.diff(clock)
    assert (steps > 0).all() and (steps % DT == 0).all()
    assert np.median(steps) == DT and len(clock) > 100  # an observer joins when it is ready


def test_tf_is_a_tree_under_map(live: Live) -> None:
    parent = {}
    for msg in [*_by(live, "/tf_static"), *_by(live, "/tf")]:
        for t in msg.transforms:
            assert parent.setdefault(t.child_frame_id, t.header.frame_id) == t.header.frame_id
    for frame in parent:
        chain = [frame]
        while chain[-1] != "map":
            chain.append(parent[chain[-1]])
            assert len(chain) < 8, chain
    assert {"ego/base_link", "b1/base_link", "ego/cam_optical", "ego/lidar"} <= set(parent)


def _csv(run: Path, name: str) -> dict[int, dict[str, str]]:
    with open(run / name) as f:
        return {int(row["stamp_ns"]): row for row in csv.DictReader(f)}


def test_navsatfix_is_the_gps_sample_and_imu_has_covariances(live: Live) -> None:
    gps = _csv(live.run, "sensor.ego.gps.csv")
    fixes = _by(live, "/ego/gps/fix")
    for fix in fixes:
        row = gps[stamp_ns(fix.header)]
        assert fix.latitude == pytest.approx(float(row["latitude[deg]"]), abs=1e-9)
        assert fix.longitude == pytest.approx(float(row["longitude[deg]"]), abs=1e-9)
        assert fix.position_covariance[0] == pytest.approx(float(row["horizontal_sigma[m]"]) ** 2)
    imu = _by(live, "/ego/imu/imu")[-1]
    assert imu.header.frame_id == "ego/imu"
    assert imu.angular_velocity_covariance[0] == pytest.approx(0.009**2 + 0.0008**2)


def test_images_have_their_sizes_and_encodings(live: Live) -> None:
    for name, encoding in ENCODINGS.items():
        img = _by(live, f"/ego/cam/{name}")[-1]
        assert (img.encoding, img.width, img.height, img.header.frame_id) == (
            encoding, 80, 60, "ego/cam_optical")  # fmt: skip
        assert len(img.data) == img.step * img.height
    info = _by(live, "/ego/cam/camera_info")[-1]
    assert (info.width, info.height) == (80, 60) and info.k[2] == 39.5
    ppi = _by(live, "/ego/radar/ppi")[-1]
    assert (ppi.encoding, ppi.width, ppi.height) == ("mono8", 256, 256)


def test_lidar_sees_the_buoy_where_it_is(live: Live) -> None:
    """A known point: the buoy's returns, taken to `map` with /tf_static and the ego's odom
    at the scan's stamp, lie on the buoy (9, 0)."""
    odom = {stamp_ns(o.header): o.pose.pose for o in _by(live, "/ego/odom")}
    (static,) = _by(live, "/tf_static")
    mount = next(t.transform for t in static.transforms if t.child_frame_id == "ego/lidar")
    cloud = next(c for c in _by(live, "/ego/lidar/points") if stamp_ns(c.header) in odom)
    rows = np.frombuffer(bytes(cloud.data), np.uint8).reshape(-1, cloud.point_step)
    buoy = rows[rows[:, 18] == 4]
    assert len(buoy) > 3
    xyz = buoy[:, :12].copy().view("<f4").astype(np.float64)
    pose = odom[stamp_ns(cloud.header)]
    q = mount.rotation
    in_body = xyz @ rotations.matrix((q.x, q.y, q.z, q.w)).T + (
        mount.translation.x, mount.translation.y, mount.translation.z)  # fmt: skip
    o = pose.orientation
    in_map = in_body @ rotations.matrix((o.x, o.y, o.z, o.w)).T + (
        pose.position.x, pose.position.y, pose.position.z)  # fmt: skip
    assert np.hypot(in_map[:, 0] - 9.0, in_map[:, 1]).max() < 0.6


def test_cmd_vel_drives_each_vessel_in_its_convention(live: Live) -> None:
    """Surge within 5 % of the command, from 3 s after the first one arrived (settled)."""
    messages = read_mcap_messages(live.run / "run.mcap")
    for vessel, surge in COMMANDED.items():
        commands = [m for m in messages if m.topic == f"/{vessel}/cmd_vel"]
        assert commands and {m.decoded.linear.x for m in commands} == {surge}
        settled = commands[0].log_time + 3 * 10**9
        rows = _csv(live.run, f"vessel.{vessel}.state.csv")
        late = [float(r["linear_velocity_x[m/s]"]) for s, r in rows.items() if s > settled]
        assert len(late) > 100 and abs(np.mean(late) - surge) < 0.05 * surge, np.mean(late)


def test_malformed_commands_are_logged_at_most_once_a_second(live: Live) -> None:
    log = (live.run / "log" / "ros.log").read_text()
    bad = re.findall(r"on /ego/cmd_vel: malformed ROS command: not little-endian CDR", log)
    wrong = re.findall(r"on /other/cmd_vel: malformed ROS command: not a geometry_msgs/msg/Tw", log)
    assert 1 <= len(bad) <= 2 and 1 <= len(wrong) <= 2, log[-3000:]
