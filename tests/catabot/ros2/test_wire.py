"""Type hashes, keys, attachments and graph tokens, against published values and the
conventions as their sources state them (../shared/reference/ros2-over-zenoh.md)."""

from __future__ import annotations

import pytest
from zenoh.ext import Int64, z_serialize

from catabot.ros2 import types, wire

PUBLISHED = {  # RIHS01 of Jazzy types: rmw_zenoh's design.md and a third-party table
    "std_msgs/msg/String": "df668c740482bbd48fb39d76a70dfd4bd59db1288021743503259e948f6b1a18",
    "geometry_msgs/msg/Twist": "9c45bf16fe0983d80e3cfe750d6835843d265a9a6c46bd2e609fcddde6fb8d2a",
    types.CLOCK: "692f7a66e93a3c83e71765d033b60349ba68023a8c689a79e48078bcb5c58564",
    types.IMU: "7d9a00ff131080897a5ec7e26e315954b8eae3353c3f995c55faf71574000b5b",
    types.POINTCLOUD2: "9198cabf7da3796ae6fe19c4cb3bdd3525492988c70522628af5daa124bae2b5",
    types.NAVSATFIX: "62223ab3fe210a15976021da7afddc9e200dc9ec75231c1b6a557fc598a65404",
    types.ODOMETRY: "3cc97dc7fb7502f8714462c526d369e35b603cfc34d946e3f2eda2766dfec6e0",
    types.TF: "e369d0f05a23ae52508854b66f6aa0437f3449d652e8cbf22d5abe85d020f087",
    types.IMAGE: "d31d41a9a4c4bc8eae9be757b0beed306564f7526c88ea6a4588fb9582527d47",
    types.CAMERA_INFO: "b3dfd68ff46c9d56c80fd3bd4ed22c7a4ddce8c8348f2f59c299e73118e7e275",
}


@pytest.mark.parametrize("typename", sorted(PUBLISHED))
def test_type_hashes_are_the_published_ones(typename: str) -> None:
    assert types.rihs01(typename) == "RIHS01_" + PUBLISHED[typename]


def test_rmw_zenoh_key_has_domain_topic_dds_type_and_hash() -> None:
    assert wire.rmw_key(0, "/chatter", "std_msgs/msg/String") == (
        "0/chatter/std_msgs::msg::dds_::String_/RIHS01_" + PUBLISHED["std_msgs/msg/String"]
    )  # rmw_zenoh design.md's example
    key = wire.rmw_key(7, "/ego/cmd_vel", "geometry_msgs/msg/Twist")
    assert key.startswith("7/ego/cmd_vel/geometry_msgs::msg::dds_::Twist_/RIHS01_9c45bf16")


@pytest.mark.parametrize(
    "topic, namespace, key",
    [("/cmd_vel", "/", "cmd_vel"), ("/robot1/odom", "/", "robot1/odom"),
     ("/cmd_vel", "/bot1", "bot1/cmd_vel"), ("/tf_static", "/a/b", "a/b/tf_static")],
)  # fmt: skip
def test_bridge_key_is_the_topic_after_the_bridge_namespace(
    topic: str, namespace: str, key: str
) -> None:
    assert wire.bridge_key(topic, namespace) == key


def test_attachment_is_zenoh_ext_serialization_of_seq_stamp_gid() -> None:
    gid = bytes(range(16))
    ours = wire.attachment(42, 1_700_000_000_000_000_000, gid)
    theirs = z_serialize((Int64(42), Int64(1_700_000_000_000_000_000), gid)).to_bytes()
    assert ours == theirs and len(ours) == 33
    assert wire.parse_attachment(ours) == (42, 1_700_000_000_000_000_000, gid)
    with pytest.raises(ValueError, match="not an rmw_zenoh attachment"):
        wire.parse_attachment(ours[:-1])


def test_rmw_tokens_are_design_md_examples() -> None:
    node = wire.RmwNode(2, "8b20917502ee955ac4476e0266340d5c", "talker")
    token = node.entity_token(10, "MP", "/chatter", "std_msgs/msg/String", wire.Qos(depth=7))
    assert token == (
        "@ros2_lv/2/8b20917502ee955ac4476e0266340d5c/0/10/MP/%/%/talker/%chatter/"
        f"std_msgs::msg::dds_::String_/RIHS01_{PUBLISHED['std_msgs/msg/String']}/::,7:,:,:,,"
    )
    listener = wire.RmwNode(2, "aac3178e146ba6f1fc6e6a4085e77f21", "listener")
    assert listener.token() == "@ros2_lv/2/aac3178e146ba6f1fc6e6a4085e77f21/0/0/NN/%/%/listener"


def test_rmw_qos_leaves_defaults_empty() -> None:
    assert wire.rmw_qos(wire.Qos(depth=10)) == "::,10:,:,:,,"
    assert wire.rmw_qos(wire.Qos(depth=1, transient_local=True)) == ":1:,1:,:,:,,"
    assert wire.rmw_qos(wire.Qos(depth=1, reliable=False)) == "2::,1:,:,:,,"
    assert wire.rmw_qos(wire.Qos(depth=42)) == "::,:,:,:,,"


def test_bridge_token_escapes_slashes_and_carries_the_type_hash() -> None:
    token = wire.bridge_token("abc", "MP", "ego/odom", types.ODOMETRY, wire.Qos(depth=10))
    assert token == (
        "@/abc/@ros2_lv/MP/ego§odom/nav_msgs§msg§Odometry/"
        f":1:0:0,10:typehash=RIHS01_{PUBLISHED[types.ODOMETRY]};"
    )
    latched = wire.bridge_token("abc", "MP", "tf_static", types.TF, wire.Qos(1, True))
    assert latched.endswith(f"/:1:1:0,1:typehash=RIHS01_{PUBLISHED[types.TF]};")


def test_gid_is_stable_and_sixteen_bytes() -> None:
    assert wire.gid("@ros2_lv/0/x") == wire.gid("@ros2_lv/0/x") != wire.gid("@ros2_lv/0/y")
    assert len(wire.gid("t")) == 16


def test_modes_choose_conventions() -> None:
    assert wire.conventions("both") == (wire.Convention.BRIDGE, wire.Convention.RMW)
    assert wire.conventions("bridge") == (wire.Convention.BRIDGE,)
    assert wire.conventions("rmw_zenoh") == (wire.Convention.RMW,)
