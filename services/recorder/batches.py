"""Batches (`BodyStates`, `TwistBatch`) recorded as the per-vessel streams they stand for.

The run folder keeps one `vessel.<id>.state.csv` per body and one `/vessel/<id>/state`
Odometry channel per vessel (every body's frame is on `/tf`, one TFMessage a tick), and one
`vessel.<id>.cmd.twist.csv` / `/vessel/<id>/cmd/twist` channel per traffic boat, as if each
row had been its own message. Formatting them one message at a time
(a dataclass, a CSV writer call, an encoder call and an MCAP record each) was most of the
recorder's time with 100 boats, so each batch is formatted here in a few array-wide calls.
The bytes are exactly those of the per-message path (tests/services/recorder/test_batches.py).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from catabot.bus.messages import (
    BodyStates,
    Message,
    TwistBatch,
    TwistCmd,
    VesselState,
    check_ids,
)
from services.recorder import cdr, ros2_msgdefs, tabular

# json_schemas.encode of a TwistCmd, field by field: {"surge":..,"yaw_rate":..,"tick":..,..}
# (JSON keeps repr: it is two floats a boat, and JSON readers expect round-trip values)
_TWIST_JSON = '{"surge":%r,"yaw_rate":%r,"tick":%d,"stamp_ns":%d}'


@dataclass(frozen=True)
class Block:
    """Row i of a batch as a sample of `streams[i]`: its CSV line and its MCAP payload,
    either one by one (None where it cannot be encoded: JSON has no NaN) or, for payloads
    built as byte matrices, as (rows, (len(rows), L) matrix) groups."""

    cls: type[Message]
    stamp_ns: int
    streams: tuple[str, ...]
    lines: list[str]
    payloads: list[bytes | None] = field(default_factory=list)
    groups: list[tuple[np.ndarray, np.ndarray]] = field(default_factory=list)
    tf: bytes | None = None  # every body's frame as one tf2_msgs/TFMessage, for `/tf`


class BatchFormatter:
    """Knows, for one run, which stream and which encoder each row of a batch belongs to."""

    def __init__(
        self, body_ids: tuple[str, ...], boat_ids: tuple[str, ...], *, vessels: int
    ) -> None:
        """body_ids: the `BodyStates` rows, the first `vessels` of them vessels (the rest
        buoys: a CSV each and a frame on `/tf`, but no Odometry channel, as on the bus)."""
        self.body_ids, self.boat_ids, self.vessels = body_ids, boat_ids, vessels
        self.state_streams = tuple(f"vessel/{b}/state" for b in body_ids)
        self.twist_streams = tuple(f"vessel/{b}/cmd/twist" for b in boat_ids)
        frame = ros2_msgdefs.WORLD_FRAME
        self._odometry = cdr.OdometryBatch(frame, body_ids[:vessels])
        self._tf = cdr.TfBatch(frame, body_ids)

    def states(self, batch: BodyStates) -> Block:
        """Raises ValueError for a batch of other bodies (rows would land in wrong files)."""
        check_ids("world/states", batch.tick, batch.ids, self.body_ids)
        table = np.concatenate(batch.arrays(), axis=1)  # VesselState's columns, (N, 19)
        lines = tabular.block_lines(batch.stamp_ns, batch.tick, table)
        # position, orientation, linear and angular velocity: the Odometry fields
        groups = self._odometry.encode_groups(batch.stamp_ns, table[: self.vessels, :13])
        tf = self._tf.encode(batch.stamp_ns, batch.position, batch.orientation)
        return Block(VesselState, batch.stamp_ns, self.state_streams, lines, groups=groups, tf=tf)

    def twists(self, batch: TwistBatch) -> Block:
        """Raises ValueError for a batch of other boats or of the wrong shape."""
        batch.check(self.boat_ids)
        table = np.stack((batch.surge, batch.yaw_rate), axis=1).astype(np.float64)
        lines = tabular.block_lines(batch.stamp_ns, batch.tick, table)
        return Block(TwistCmd, batch.stamp_ns, self.twist_streams, lines, _twist_json(batch, table))


def _twist_json(batch: TwistBatch, table: np.ndarray) -> list[bytes | None]:
    """Each row's JSON; None for a row with NaN or inf (JSON has none). All rows finite
    (every tick but a faulty one): one format call and one split for the whole block."""
    tail = (batch.tick, batch.stamp_ns)
    finite = np.isfinite(table).all(axis=1)
    if finite.all():
        line = _TWIST_JSON.replace("%r", "%%r") % tail  # the row's two floats still to fill
        text = "\n".join([line] * len(table)) % tuple(table.ravel().tolist())
        return list(text.encode().split(b"\n"))
    return [
        (_TWIST_JSON % (*row, *tail)).encode() if ok else None
        for row, ok in zip(table.tolist(), finite.tolist(), strict=True)
    ]
