"""Traffic and buoys recorded at `recording.traffic_rate_hz`, scenario vessels every tick.

Why: with 100 boats, formatting every body's CSV row, Odometry and /tf entry every tick was
most of the recorder's time (Python's exact float text alone ≈0.9 ms a tick), and so of the
whole stack's, for rows users rarely read at 100 Hz: the traffic is context, the scenario
vessels are what is analysed. Metrics still see every tick (they read the bus, not files).
On the ticks between two traffic samples a batch is recorded as its scenario vessels' rows
only: their CSV lines, their Odometry and a /tf of their frames.
"""

from __future__ import annotations

import numpy as np

from catabot.bus.messages import BodyStates
from catabot.config.rates import traffic_record_period
from catabot.ros2.cdr import OdometryBatch
from catabot.ros2.convert import Converter
from catabot.ros2.frames import BodyFrames
from catabot.ros2.names import MAP


class Thinning:
    """Which ticks record every body, and the encoders of the scenario vessels alone."""

    def __init__(self, convert: Converter) -> None:
        world, names = convert.world, convert.names
        others = len(world.bodies) > sum(b.kind == "vessel" for b in world.bodies)
        self.period = traffic_record_period(world.scenario) if others else 1
        own = [b for b in world.bodies if b.kind == "vessel"]
        self.rows = np.array([b.row for b in own], dtype=np.intp)
        self.streams = tuple(f"vessel/{b.id}/state" for b in own)
        self.topics = tuple(names.odom(b.id) for b in own)
        frames = [names.base_link(b.id) for b in own]
        self._odometry, self._tf = OdometryBatch(MAP, frames), BodyFrames(names, own)

    def every_body(self, tick: int) -> bool:
        """Each tick whose state is stamped on the rate's grid, the start state (tag -1,
        stamp 0) first: the batch tagged k is stamped (k + 1) dt, so at k + 1 a multiple of
        the period it shares its stamp with the samples of a sensor of that rate (k % period
        == 0, stamped k dt) and a join on `stamp_ns` finds both (0, 0.1, 0.2 s, ...)."""
        return (tick + 1) % self.period == 0

    def table(self, batch: BodyStates) -> np.ndarray:
        """The scenario vessels' rows, VesselState's 19 columns: their rows taken first (a
        few), not every body's concatenated and then picked."""
        return np.concatenate([np.take(a, self.rows, axis=0) for a in batch.arrays()], axis=1)

    def odometry_groups(
        self, stamp_ns: int, table: np.ndarray
    ) -> list[tuple[np.ndarray, np.ndarray]]:
        """`table`'s pose and velocities (its first 13 columns) as odometry."""
        return self._odometry.encode_groups(stamp_ns, np.ascontiguousarray(table[:, :13]))

    def tf(self, batch: BodyStates) -> bytes:
        return self._tf.encode(batch)
