"""The recorder: a stepping participant that writes every stream of the world to disk.

It steps in lockstep so nothing is dropped: at tick k it waits for every sample due
from ticks < k and writes them in tick order. Files receive whole ticks only, every 0.1 s
of wall time and at the end, so a recorder killed at any moment leaves readable CSV and
MCAP up to a complete tick at most 0.1 s (wall) old; any other ending records every tick.
"""

from __future__ import annotations

import dataclasses
import logging
import sys
import time
from collections import deque
from collections.abc import Callable
from pathlib import Path
from typing import Any

from catabot.bus.clock import NS_PER_S
from catabot.bus.inbox import Inputs
from catabot.bus.messages import (
    BodyStates,
    End,
    Message,
    SettingsChange,
    Tick,
    TwistBatch,
    WaypointsCmd,
)
from catabot.bus.settings import changes_of
from catabot.bus.taken import taken
from catabot.config.load import scenario_json
from catabot.config.scenario import Scenario
from catabot.ros2.convert import Converter
from catabot.run.service import Built, ServiceContext, run_service
from catabot.world.orders import Orders, command_timeouts
from services.recorder.batches import BatchFormatter, Block, without
from services.recorder.csv_sink import CsvSink, RecorderError
from services.recorder.dataset import Dataset
from services.recorder.mcap_recording import McapRecording
from services.recorder.metrics import Metrics
from services.recorder.scripts import ScriptedCommands
from services.recorder.split_record import SplitRecord

log = logging.getLogger("recorder")
FLUSH_EVERY_S = 0.1


RECORDED = (".csv", ".mcap", ".rrd")  # and the folders and files below, a run's recording
RECORDED_NAMES = ("metrics.json", "dataset", "export")


def _fresh_folder(run_dir: Path, scenario: Scenario) -> None:
    """The run folder holds this run alone. Used again (a compose file's fixed folder, one
    --run-dir given twice) it kept the last run's files beside this run's, those of the same
    name replaced: one folder, two runs, nothing said when their scenarios were the same.
    Refused, as rosbag2 refuses an output folder that exists; a scenario.json and log/ alone
    (written by `catabot run` for this run, or left by a run that never recorded) are not a
    recording."""
    found = run_dir.iterdir()
    earlier = sorted(p.name for p in found if p.suffix in RECORDED or p.name in RECORDED_NAMES)
    if earlier:
        shown = ", ".join(earlier[:4]) + (f" and {len(earlier) - 4} more" if earlier[4:] else "")
        raise RecorderError(
            f"run folder {run_dir} already holds a recording ({shown}): give this run a "
            "folder of its own (--run-dir; compose: CATABOT_RUN=<name>) or move those away"
        )
    own, text = run_dir / "scenario.json", scenario_json(scenario)
    if not own.is_file() or own.read_text() != text:
        own.write_text(text)


class Recorder:
    def __init__(self, ctx: ServiceContext) -> None:
        rec = ctx.scenario.recording
        ctx.run_dir.mkdir(parents=True, exist_ok=True)
        _fresh_folder(ctx.run_dir, ctx.scenario)
        self.account = SplitRecord(ctx.run_dir, ctx.scenario)
        self.keys = ctx.keys
        world = ctx.world
        convert = Converter(world, ctx.scenario.ros)  # the gateway's topics and frames
        self.csv = CsvSink(ctx.run_dir) if rec.csv else None
        self.mcap = (
            McapRecording(ctx.run_dir, convert, compression=rec.mcap_compression)
            if rec.mcap
            else None
        )
        self.dataset = Dataset(ctx.run_dir / "dataset", world)
        streams = world.streams.lockstep()  # free commands: as physics took them (taken.py)
        free = [*world.streams.commands, *world.streams.waypoints]
        self.free_kinds = {self.keys.relative(s.key): s.message for s in free}
        self.batches = BatchFormatter(convert)
        self.orders = Orders(command_timeouts(world.vessels))  # physics' rule: written, metered
        self.driven_by = world.driven_by  # the vessels a dropped participant drove
        k = self.keys
        self.commanded = {
            key(v.id): v.id
            for v in world.vessels
            for key in (k.cmd_thrust, k.cmd_twist, k.cmd_waypoints)
        }  # traffic boats too: their set-points yield alike
        self.metrics = Metrics(world, self.orders)
        self.scripts = ScriptedCommands(world, self.orders)
        self.run_dir = ctx.run_dir
        self.start = world.start_states()
        self.limits, self.dt_ns = world.clock_limits, world.scenario.dt_ns
        self._held: deque[tuple[Tick, Inputs]] = deque()  # stepped, not yet known final
        self._flushed_at = 0.0
        self.changes_stream = self.keys.relative(self.keys.config_changes())
        self.participant = ctx.participant(streams)

    def step(self, tick: Tick, inputs: Inputs) -> None:
        self._held.append((tick, inputs))
        self._write_final(self.limits.acked_by_all(self.participant.granted) + 1)
        self._flush()

    def _write_final(self, upto: int) -> None:
        """Write the ticks stepped up to `upto`. A tick is final once every participant has
        acked the one before it (`ClockLimits.acked_by_all`): a participant that ends the run
        ends it no earlier, so nothing is written past the run's end, whoever ends it and
        however far this one had stepped ahead."""
        while self._held and self._held[0][0].tick <= upto:
            self._record(*self._held.popleft())

    def _record(self, tick: Tick, inputs: Inputs) -> None:
        if tick.tick == 0:  # the state at t = 0 (tagged -1): where every body starts
            self._states(self.keys.relative(self.keys.world_states()), self.start)
        self._inputs(tick, inputs)
        for stream, cmd in self.scripts.due(tick.tick, tick.stamp_ns):  # as if sent
            self._write(stream, cmd)

    def _inputs(self, tick: Tick, inputs: Inputs) -> None:
        """The states first: their batch names the free commands physics took at its tick,
        and a boat one took over does not follow that tick's traffic set-points (sorted by
        key, `world/cmd/twist` came first and wrote a set-point row the boat ignored)."""
        states = self.keys.world_states()
        for key in sorted(inputs, key=lambda k: (k != states, k)):
            stream = self.keys.relative(key)
            for msg in inputs[key]:
                if isinstance(msg, BodyStates):
                    self._taken(msg, tick)  # first: the order in force over this batch's tick
                    self._states(stream, msg)
                elif isinstance(msg, TwistBatch):
                    self._write_block(stream, msg, self._twists)
                else:
                    self._write(stream, _stamped(msg, tick))
                    self._heard(key, msg, tick)
        for change in changes_of(tick.settings):  # what took effect at this tick: an input
            record = SettingsChange(tick.tick, tick.stamp_ns, change.key, change.value)
            self._write(self.changes_stream, record)

    def _states(self, stream: str, batch: BodyStates) -> None:
        if self._write_block(stream, batch, self.batches.states):
            self.metrics.add(batch)  # only batches of this run's bodies

    def _taken(self, batch: BodyStates, tick: Tick) -> None:
        """The free commands physics took at the start of the batch's tick k: written as
        heard before tick k (k - 1, stamped k dt), the order physics follows from k on."""
        at = dataclasses.replace(tick, tick=batch.tick, stamp_ns=batch.stamp_ns - self.dt_ns)
        self._drops(at)
        for text in batch.commands:
            try:
                key, msg = taken(text, self.free_kinds)
            except ValueError as exc:
                log.error("not recorded: %s", exc)
                continue
            self._write(key, _stamped(msg, at))
            self._heard(f"{self.keys.prefix}/{key}", msg, at)
        for vessel in self.orders.expire(at.stamp_ns):  # as physics, after that tick's takes
            self._resume(vessel, at)

    def _drops(self, at: Tick) -> None:
        """Participants dropped (clock.policy drop) whose vessels physics handed back at this
        batch's tick (Inbox.stalled_by: the same streams and samples here), so their
        script's step, or rest, is written from there."""
        for name in self.participant.inbox.stalled_by(at.tick):
            self.metrics.dropped[name] = at.stamp_ns / NS_PER_S
            for vessel in self.driven_by([name]):
                self.orders.drop(vessel)
                self._resume(vessel, at)

    def _heard(self, key: str, msg: Message, tick: Tick) -> None:
        """A command for a vessel: the order physics follows from now on, so an overridden
        script's steps are not written and the thrust metered is the one in force; after a
        release, the script's step (or rest) it follows again, written as a command."""
        vessel = self.commanded.get(key)
        if vessel is None or not self.orders.heard(vessel, msg, stamp_ns=tick.stamp_ns):
            return
        if isinstance(msg, WaypointsCmd):
            self._resume(vessel, tick)
        else:
            self.metrics.order_changed(vessel)

    def _resume(self, vessel: str, tick: Tick) -> None:
        """A vessel handed back (a release, a stale outside command): the order it follows
        again, written as a command."""
        self.metrics.order_changed(vessel)
        resumed = self.scripts.resumed(vessel, tick.tick, tick.stamp_ns)
        if resumed is not None:
            self._write(*resumed)

    def _twists(self, batch: TwistBatch) -> Block:
        """The set-points of the boats that follow them (not those an outside command holds)."""
        return without(self.batches.twists(batch), self.scripts.taken(batch.ids))

    def _write_block(self, stream: str, msg: Any, formatter: Callable[[Any], Block]) -> bool:
        """A batch as the per-vessel rows it stands for (`batches.py`); False if refused."""
        try:
            block = formatter(msg)
        except ValueError as exc:
            log.error("not recorded: %s: %s", stream, exc)
            return False
        try:
            if self.csv is not None:
                self.csv.write_lines(block.streams, block.cls, block.lines)
            if self.mcap is not None:
                self.mcap.block(block)
        except RecorderError as exc:  # a disk that fails ends the recording: not caught here
            log.error("not recorded: %s", exc)
        return True

    def _write(self, stream: str, msg: Message) -> None:
        try:
            if self.csv is not None and not isinstance(msg, WaypointsCmd):  # a path: no row
                self.csv.write(stream, msg)
            if self.mcap is not None:
                self.mcap.message(stream, msg)
            self.dataset.write(stream, msg)
        except (RecorderError, ValueError) as exc:  # this sample only; a failing disk ends it
            log.error("not recorded: %s", exc)

    def _flush(self) -> None:
        """Whole ticks to disk, at most every `FLUSH_EVERY_S` of wall time (and at the end):
        a write per file per tick, 200 files with 100 boats, cost more than the rows."""
        now = time.monotonic()
        if now - self._flushed_at < FLUSH_EVERY_S:
            return
        self._flushed_at = now
        if self.csv is not None:
            self.csv.flush()
        if self.mcap is not None:
            self.mcap.flush()

    def on_end(self, end: End, inputs: Inputs) -> None:
        self._write_final(end.tick + 1)  # step k writes the samples of tick k - 1
        past, self._held = len(self._held), deque()  # stepped past the end: not the run's
        self._inputs(Tick(end.run, end.tick + 1, 0, 0), inputs)  # no tick after the end
        if self.csv is not None:
            self.csv.close()
        if self.mcap is not None:
            self.mcap.close()
        self.metrics.write(self.run_dir / "metrics.json", end_reason=end.reason)
        self.account.end(end)
        more = f" ({past} ticks stepped past the end left out)" if past else ""
        when = f"after tick {end.tick}" if end.tick >= 0 else "before the first tick"
        log.info("recorder closed its files %s%s", when, more)


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
