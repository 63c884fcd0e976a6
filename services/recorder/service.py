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
from catabot.messages import CameraFrame, End, Message, Tick
from catabot.participant import Participant
from catabot.service import Built, ServiceContext, run_service
from catabot.streams import command_streams, world_streams
from services.recorder import images
from services.recorder.csv_sink import CsvSink, RecorderError
from services.recorder.dataset import Dataset
from services.recorder.mcap_sink import McapSink

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
        self.participant = Participant(
            ctx.session, ctx.keys, ctx.name, inputs=streams, peers=ctx.peers
        )

    def step(self, tick: Tick, inputs: Inputs) -> None:
        for key in sorted(inputs):
            stream = self.keys.relative(key)
            for msg in inputs[key]:
                self._write(stream, _stamped(msg, tick))
        self._flush()

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
        log.info("recorder closed its files after tick %d", end.tick)


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
