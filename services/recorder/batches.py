"""Batches (`BodyStates`, `TwistBatch`) recorded as the per-vessel streams they stand for.

The run folder keeps one `vessel.<id>.state.csv` per body and one `vessel.<id>.cmd.twist.csv`
per traffic boat, as if each row had been its own message; `run.mcap` has every vessel's
`<ns>/odom` (nav_msgs/Odometry), one `/tf` a tick for every body and each boat's set-points
on `<ns>/cmd_vel` (geometry_msgs/Twist), the gateway's topics (catabot/ros2/convert.py).
Formatting them one message at a time (a dataclass, a CSV writer call, an encoder call and
an MCAP record each) was most of the recorder's time with 100 boats, so each batch is
formatted here in a few array-wide calls; the bytes are those of the per-message path
(tests/services/recorder/test_batches.py).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import NDArray

from catabot.bus.messages import (
    BodyStates,
    Message,
    TwistBatch,
    TwistCmd,
    VesselState,
    check_ids,
)
from catabot.ros2 import types
from catabot.ros2.convert import Converter
from services.recorder import tabular
from services.recorder.thinning import Thinning


@dataclass(frozen=True)
class Block:
    """Row i of a batch as a sample of `streams[i]` (its CSV line), and the batch's ROS 2
    messages: (indices into `topics`, (k, L) byte matrix) groups of `typename`, and for
    states every body's frame as one TFMessage for `/tf`."""

    cls: type[Message]
    stamp_ns: int
    streams: tuple[str, ...]
    lines: list[str]
    topics: tuple[str, ...]
    typename: str
    groups: list[tuple[np.ndarray, np.ndarray]]
    tf: bytes | None = None
    family: tuple[str, ...] = ()  # topics whose channels are declared together, in order


def without(block: Block, skip: NDArray[np.bool_]) -> Block:
    """The block less the rows `skip` marks (CSV lines and ROS messages alike)."""
    if not skip.any():
        return block
    keep = np.flatnonzero(~skip)
    groups = [(rows[~skip[rows]], matrix[~skip[rows]]) for rows, matrix in block.groups]
    return replace(
        block,
        streams=tuple(block.streams[i] for i in keep),
        lines=[block.lines[i] for i in keep],
        groups=[(rows, matrix) for rows, matrix in groups if len(rows)],
    )


class BatchFormatter:
    """Knows, for one run, which stream, file and topic each row of a batch belongs to."""

    def __init__(self, convert: Converter) -> None:
        world = convert.world
        self.convert = convert
        self.state_streams = tuple(f"vessel/{b}/state" for b in world.body_ids)
        self.twist_streams = tuple(f"vessel/{b}/cmd/twist" for b in world.boat_ids)
        self.twist_blocks = _slices(list(world.traffic_blocks.values()))
        self.thin = Thinning(convert)
        self.every_line = tabular.BlockLines()  # every body's rows (resting buoys: the same)
        self.vessel_line = tabular.BlockLines()  # the scenario vessels' rows between

    def states(self, batch: BodyStates) -> Block:
        """Raises ValueError for a batch of other bodies (rows would land in wrong files).
        Between two traffic samples (thinning.py), the scenario vessels' rows only."""
        if not self.thin.every_body(batch.tick):
            check_ids("world/states", batch.tick, batch.ids, self.convert.world.body_ids)
            return self._vessels_only(batch)
        groups = self.convert.odometry_groups(batch)  # checks the rows first
        table = np.concatenate(batch.arrays(), axis=1)  # VesselState's columns, (N, 19)
        lines = self.every_line(batch.stamp_ns, batch.tick, table)
        return Block(
            VesselState, batch.stamp_ns, self.state_streams, lines,
            self.convert.odom_topics, types.ODOMETRY, groups, tf=self.convert.tf(batch),
        )  # fmt: skip

    def _vessels_only(self, batch: BodyStates) -> Block:
        thin = self.thin
        table = thin.table(batch)
        lines = self.vessel_line(batch.stamp_ns, batch.tick, table)
        return Block(
            VesselState, batch.stamp_ns, thin.streams, lines, thin.topics, types.ODOMETRY,
            thin.odometry_groups(batch.stamp_ns, table), tf=thin.tf(batch),
        )  # fmt: skip

    def twists(self, batch: TwistBatch) -> Block:
        """Raises ValueError for a batch of other boats or of the wrong shape."""
        block = self.twist_blocks.get(tuple(batch.ids))  # a traffic shard's boats
        if block is None:
            raise ValueError(f"twist batch at tick {batch.tick} lists {list(batch.ids)[:8]}, "
                             "expected one traffic shard's boats")  # fmt: skip
        rows = self.convert.boat_twists(batch, tuple(batch.ids))  # checks shapes first
        table = np.stack((batch.surge, batch.yaw_rate), axis=1).astype(np.float64)
        lines = tabular.block_lines(batch.stamp_ns, batch.tick, table)
        groups = [(np.arange(len(rows)), rows)]
        topics = self.convert.boat_twist_topics[block]
        return Block(
            TwistCmd, batch.stamp_ns, self.twist_streams[block], lines, topics, types.TWIST, groups,
            family=self.convert.boat_twist_topics,  # one order of channels for any traffic shards
        )  # fmt: skip


def _slices(blocks: list[tuple[str, ...]]) -> dict[tuple[str, ...], slice]:
    """Each traffic shard's boats -> its rows among every boat's (blocks are contiguous)."""
    out, start = {}, 0
    for ids in blocks:
        out[ids] = slice(start, start + len(ids))
        start += len(ids)
    return out
