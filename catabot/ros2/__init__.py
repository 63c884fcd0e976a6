"""ROS 2 for the whole project: one CDR layer and one conversion from bus messages to ROS 2
topics, used by the recorder (`run.mcap`) and by the gateway (services/ros) alike, so a
recording and a live run show the same topics, types and frames (DESIGN.md §8).

- `types`: message definitions and RIHS01 type hashes, from rosbags' Jazzy typestore;
- `cdr`, `cdr_more`: hand-written encoders where they are faster, pinned to rosbags' bytes;
- `names`, `frames`: topic names per vessel namespace, frame ids and the static transforms;
- `convert`, `convert_sensors`: bus messages in, (topic, type, CDR) out;
- `wire`: the two Zenoh conventions (zenoh-bridge-ros2dds, rmw_zenoh): keys, attachments,
  liveliness tokens; `commands`: ROS commands back to bus messages, checked.
"""
