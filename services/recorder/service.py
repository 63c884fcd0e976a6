"""The recorder: a stepping participant that writes every stream of the world to disk.

It steps in lockstep so nothing is dropped: at tick k it waits for every sample due
from ticks < k, writes them in tick order, and flushes, so a run killed at any moment
leaves readable CSV and MCAP up to the last complete tick.
"""

from __future__ import annotations

import dataclasses
import logging
import sys

from catabot.inbox import Inputs
from catabot.messages import BodyStates, CameraFrame, End, Message, Tick
from catabot.participant import Participant
from catabot.service import Built, ServiceContext, run_service
from catabot.streams import BodyRows, body_ids, command_streams, world_streams
from catabot.traffic_plan import all_vessels
from services.recorder import images
from services.recorder.csv_sink import CsvSink, RecorderError
from services.recorder.dataset import Dataset
from services.recorder.mcap_sink import McapSink
from services.recorder.metrics import Metrics

log = logging.getLogger("recorder")


class Recorder:
    def __init__(self, ctx: ServiceContext) -> None:
        rec = ctx.scenario.recording
        ctx.run_dir.mkdir(parents=True, exist_ok=True)
        self.keys = ctx.keys
        self.csv = CsvSink(ctx.run_dir) if rec.csv else None
        self.mcap = McapSink(ctx.run_dir / "run.mcap") if rec.mcap else None
        self.dataset = Dataset(ctx.run_dir / "dataset", ctx.scenario)
        streams = world_streams(ctx.scenario, ctx.keys) + command_streams(ctx.scenario, ctx.keys)
        self.states_key = ctx.keys.world_states()
        self.body_rows = BodyRows(body_ids(ctx.scenario))
        self.state_keys = [ctx.keys.vessel_state(vid) for vid in self.body_rows.expected]
        self.metrics = Metrics([v.id for v in all_vessels(ctx.scenario)])
        self.run_dir = ctx.run_dir
        self.participant = Participant(
            ctx.session, ctx.keys, ctx.name, inputs=streams, peers=ctx.peers
        )

    def step(self, tick: Tick, inputs: Inputs) -> None:
        for batch in inputs.get(self.states_key, []):
            assert isinstance(batch, BodyStates)
            self.metrics.add(batch)
        inputs = self._per_body(inputs)
        for key in sorted(inputs):
            stream = self.keys.relative(key)
            for msg in inputs[key]:
                self._write(stream, _stamped(msg, tick))
        self._flush()

    def _per_body(self, inputs: Inputs) -> Inputs:
        return per_body(inputs, self.states_key, self.state_keys, self.body_rows)

    def _write(self, stream: str, msg: Message) -> None:
        try:
            if self.csv is not None:
                self.csv.write(stream, msg)
            if self.mcap is not None:
                self._write_mcap(stream, msg)
            self.dataset.write(stream, msg)
        except (RecorderError, OSError, ValueError) as exc:
            log.error("not recorded: %s", exc)

    def _write_mcap(self, stream: str, msg: Message) -> None:
        """One channel per stream; a camera gets one Image channel per output instead."""
        assert self.mcap is not None
        stamp_ns = int(getattr(msg, "stamp_ns", 0))
        if isinstance(msg, CameraFrame):
            for output in images.outputs(msg):
                self.mcap.write(f"{stream}/{output}", msg, stamp_ns=stamp_ns)
        else:
            self.mcap.write(stream, msg, stamp_ns=stamp_ns)

    def _flush(self) -> None:
        if self.csv is not None:
            self.csv.flush()
        if self.mcap is not None:
            self.mcap.flush()

    def on_end(self, end: End, inputs: Inputs) -> None:
        self.step(Tick(end.run, end.tick + 1, 0, 0), inputs)
        if self.csv is not None:
            self.csv.close()
        if self.mcap is not None:
            self.mcap.close()
        self.metrics.write(self.run_dir / "metrics.json")
        log.info("recorder closed its files after tick %d", end.tick)


def per_body(inputs: Inputs, batch_key: str, state_keys: list[str], rows: BodyRows) -> Inputs:
    """Each `BodyStates` row as the `VesselState` of `vessel/<id>/state` (buoys too): the
    recorded files stay one CSV and one Odometry channel per body, as before the batch, and
    the batch itself is not recorded. `state_keys[i]` is the key of row i."""
    batches = inputs.get(batch_key)
    if not batches:
        return inputs
    out = {k: v for k, v in inputs.items() if k != batch_key}
    for batch in batches:
        assert isinstance(batch, BodyStates)
        rows.check(batch)
        for key, state in zip(state_keys, batch.rows(), strict=True):
            out.setdefault(key, []).append(state)
    return out


def _stamped(msg: Message, tick: Tick) -> Message:
    """Samples from outside the lockstep (tick -1) are recorded at the tick they arrived."""
    if getattr(msg, "tick", 0) == -1:
        return dataclasses.replace(msg, tick=tick.tick - 1, stamp_ns=tick.stamp_ns)  # type: ignore[call-arg]
    return msg


def build(ctx: ServiceContext) -> Built:
    recorder = Recorder(ctx)
    return recorder.participant, recorder.step, recorder.on_end


def main(argv: list[str] | None = None) -> int:
    return run_service("recorder", build, argv)


if __name__ == "__main__":
    sys.exit(main())
