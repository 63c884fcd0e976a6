"""What rosbag2 reads from an MCAP file besides its messages: each channel's offered QoS and
the `rosbag2` metadata record, so `ros2 bag play run.mcap` offers what the gateway offered
(`/tf_static` and `/buoys` TRANSIENT_LOCAL: RViz's latched subscriptions take them).

The QoS are written as Humble's rosbag2 writes them, integers, in a file whose `rosbag2`
record has no `serialized_metadata`: Humble reads integers only, and Jazzy and later read
such a file as a version-8 bag, whose QoS are integers (rosbag2_storage_mcap's
`read_metadata`); written as Jazzy writes them (names), Humble could not read the file.
"""

from __future__ import annotations

from catabot.ros2.wire import Qos

# rmw's enum values (rmw/types.h): history KEEP_LAST, reliability RELIABLE / BEST_EFFORT,
# durability TRANSIENT_LOCAL / VOLATILE, liveliness AUTOMATIC
KEEP_LAST, RELIABLE, BEST_EFFORT, TRANSIENT_LOCAL, VOLATILE, AUTOMATIC = 1, 1, 2, 1, 2, 1
METADATA_NAME = "rosbag2"
METADATA = {"ROS_DISTRO": "humble"}  # the QoS format's; no serialized_metadata: see above


def offered_qos_profiles(qos: Qos) -> str:
    """A channel's `offered_qos_profiles`: one publisher's profile as rosbag2's YAML;
    durations 0 (unspecified: the ROS defaults)."""
    lines = [
        f"- history: {KEEP_LAST}",
        f"  depth: {qos.depth}",
        f"  reliability: {RELIABLE if qos.reliable else BEST_EFFORT}",
        f"  durability: {TRANSIENT_LOCAL if qos.transient_local else VOLATILE}",
        *_duration("deadline"),
        *_duration("lifespan"),
        f"  liveliness: {AUTOMATIC}",
        *_duration("liveliness_lease_duration"),
        "  avoid_ros_namespace_conventions: false",
    ]
    return "\n".join(lines)


def _duration(name: str) -> list[str]:
    return [f"  {name}:", "    sec: 0", "    nsec: 0"]
