"""The live view: an observer of a running simulation, never a lockstep participant.

It declares no liveliness token, acks nothing and is in no stream table, so the conductor
never waits for it. Every subscription hands samples to a bounded Zenoh `RingChannel`,
filled by Zenoh's own threads without Python: when the viewer falls behind, the oldest
samples are dropped there and the publishers' sends never back up into the lockstep. The
main loop wakes `FPS` times a second, takes the newest state, scan and frame (and every radar
sweep and IMU sample still held, which are small), and logs them. Zenoh's threads keep the
normal priority; the logging thread and rerun's threads run at nice 10 (Linux nice is per
thread), so on a busy machine the simulation gets the CPU first and the view drops frames.
"""

from __future__ import annotations

import json
import logging
import os
import time
from collections import Counter, deque
from collections.abc import Callable
from pathlib import Path
from typing import Any

import rerun as rr
import zenoh

from catabot.bus import codec
from catabot.bus.identity import Roster
from catabot.bus.messages import BodyStates, End, Message, ThrustCmd, TwistCmd
from catabot.bus.session import linked
from catabot.bus.vanished import ConductorWatch
from catabot.config.sensors import SENSOR_TYPES
from catabot.run.ending import finished, run_record
from catabot.world.world import MountedSensor, World
from services.viewer.logger import RunLogger

log = logging.getLogger("viewer")
FPS = 20.0
HELD = {"lidar": 2, "camera": 2, "radar": 256, "imu": 1024}  # samples a ring keeps
METRICS_WAIT_S = 5.0  # the recorder writes metrics.json just after the run's end
LINK_S = 20.0  # how long a view waits for a link (a first one, or one lost mid-run)
LOST_S = 3.0  # no peer nor router this long, its run.json written: the run is gone


class LiveView:
    def __init__(self, session: zenoh.Session, world: World) -> None:
        keys = world.keys
        self.world, self.session = world, session
        self.lost, self._linked_at = False, time.monotonic()  # lost: the run, before its End
        self.ever_linked = False  # a view of nothing: an endpoint where nothing answered
        ring = zenoh.handlers.RingChannel
        self.states = session.declare_subscriber(keys.world_states(), ring(2))
        self.end = session.declare_subscriber(keys.end(), ring(1))
        self.cmds = session.declare_subscriber(keys.cmds(), ring(256))
        self.sensors = [
            (s, session.declare_subscriber(s.key, ring(HELD[s.config.type])))
            for s in world.sensors
            if s.config.type in HELD
        ]
        self.conductor = ConductorWatch(session, keys, Roster())  # a killed run: no End
        self._rate: deque[tuple[float, int]] = deque(maxlen=64)  # (wall s, stamp ns)
        self._stamp_ns = 0
        self.shown: Counter[str] = Counter()  # what was drawn: states, each sensor's samples

    @staticmethod
    def linked(session: zenoh.Session, timeout_s: float = LINK_S) -> bool:
        """Whether the session reached a peer or router within `timeout_s`: from then on the
        subscriptions are known to the run (Zenoh sends declarations in order on each link)."""
        limit = time.monotonic() + timeout_s
        while time.monotonic() < limit:
            if linked(session):
                return True
            time.sleep(0.05)
        return False

    def run(self, rec: rr.RecordingStream, run_dir: Path | None) -> End | None:
        """Log until the run ends (or Ctrl-C); the End, if one came."""
        os.nice(10)  # this thread only (Linux): Zenoh's receiving threads keep their priority
        logger = RunLogger(rec, self.world)
        end: End | None = None
        try:
            while end is None:
                started = time.monotonic()
                end = _newest(self.end, End)
                self._tick(logger)
                if end is None and self._gone(run_dir):
                    self.lost = True
                    break
                time.sleep(max(0.0, 1.0 / FPS - (time.monotonic() - started)))
        except KeyboardInterrupt:
            return None
        self._tick(logger)
        _final_metrics(logger, run_dir, self._stamp_ns)
        return end

    def _gone(self, run_dir: Path | None) -> bool:
        """Whether the run is gone without an End: its conductor left LOST_S ago (its End had
        time to come), or the link has been down LOST_S once the run folder says the run is
        over, LINK_S else (a slow first link, a flap mid-run): a view that attached as the run
        ended, its End already sent, or whose link was cut, waited for the End forever."""
        now = time.monotonic()
        if linked(self.session):
            if self.conductor.gone(LOST_S):
                return True
            self._linked_at, self.ever_linked = now, True
            return False
        self.conductor.left_at = None  # a token lost with the link is no word on the run
        over = run_dir is not None and finished(run_record(run_dir))
        return now - self._linked_at > (LOST_S if over else LINK_S)

    def _tick(self, logger: RunLogger) -> None:
        batch = _newest(self.states, BodyStates)
        if batch is not None:
            logger.states(batch)
            self.shown["states"] += 1
            self._stamp_ns = batch.stamp_ns
            self._real_time_factor(logger, batch.stamp_ns)
        for sensor, sub in self.sensors:
            self._sensor(logger, sensor, sub)
        for vessel, cmd in _all(self.cmds, _command):
            if isinstance(cmd, ThrustCmd):
                logger.thrust(vessel, self._stamp_ns, cmd.thrust)
            else:
                logger.setpoints(vessel, [self._stamp_ns], [(cmd.surge, cmd.yaw_rate)])

    def _sensor(self, logger: RunLogger, sensor: MountedSensor, sub: Any) -> None:
        cls = SENSOR_TYPES[sensor.config.type].message
        kind, name = sensor.config.type, f"{sensor.vessel}.{sensor.config.name}"
        if kind in ("lidar", "camera"):
            msg = _newest(sub, cls)
            if msg is None:
                return
            self.shown[name] += 1
            if kind == "lidar":
                logger.lidar(sensor, msg)
            else:
                f: Any = msg
                logger.camera(sensor, f.stamp_ns, f.color, f.segmentation, f.boxes)
            return
        samples = _all(sub, lambda p, _k: codec.decode(p, cls))
        self.shown[name] += len(samples)
        if kind == "imu":
            logger.imu(sensor, samples)
        for sweep in samples if kind == "radar" else []:
            logger.radar(sensor, sweep)

    def _real_time_factor(self, logger: RunLogger, stamp_ns: int) -> None:
        now = time.monotonic()
        self._rate.append((now, stamp_ns))
        wall0, stamp0 = self._rate[0]
        if now - wall0 > 0.5:
            logger.rtf(stamp_ns, (stamp_ns - stamp0) / 1e9 / (now - wall0))
            while len(self._rate) > 2 and now - self._rate[0][0] > 2.0:
                self._rate.popleft()


def _command(payload: bytes, key: str) -> tuple[str, ThrustCmd | TwistCmd] | None:
    """A vessel's thrust or twist command (its path is drawn from the states)."""
    kind = {"thrust": ThrustCmd, "twist": TwistCmd}.get(key.rsplit("/", 1)[-1])
    if kind is None:
        return None
    msg: Message = codec.decode(payload, kind)
    assert isinstance(msg, ThrustCmd | TwistCmd)
    return key.split("/")[-3], msg


def _drain(sub: Any) -> list[zenoh.Sample]:
    out = []
    while (sample := sub.try_recv()) is not None:
        out.append(sample)
    return out


def _newest(sub: Any, cls: type[Message]) -> Any:
    """The newest sample held (the older ones are dropped: a view shows the present)."""
    samples = _drain(sub)
    for sample in reversed(samples):
        try:
            return codec.decode(sample.payload.to_bytes(), cls)
        except codec.CodecError as exc:
            log.warning("%s: not shown: %s", sample.key_expr, exc)
    return None


def _all(sub: Any, decode: Callable[[bytes, str], Any]) -> list[Any]:
    out = []
    for sample in _drain(sub):
        try:
            item = decode(sample.payload.to_bytes(), str(sample.key_expr))
        except codec.CodecError as exc:
            log.warning("%s: not shown: %s", sample.key_expr, exc)
            continue
        if item is not None:
            out.append(item)
    return out


def _final_metrics(logger: RunLogger, run_dir: Path | None, stamp_ns: int) -> None:
    """metrics.json of the run folder, when the recorder has written it."""
    if run_dir is None:
        return
    path, limit = run_dir / "metrics.json", time.monotonic() + METRICS_WAIT_S
    while not path.is_file() and time.monotonic() < limit:
        time.sleep(0.1)
    try:
        logger.metrics(stamp_ns, json.loads(path.read_text()))
    except (OSError, ValueError):
        log.info("no metrics.json in %s", run_dir)
