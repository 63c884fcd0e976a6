"""A recorded run into the viewer: `catabot view RUN_FOLDER`, and `run.rrd` after a run.

Everything comes from the run folder through `catabot.run.recorded` (run.mcap, and the
camera labels in dataset/), stream by stream and every sample, so the replay is complete and
the same run always gives the same recording (on `sim_time`; rerun adds its own row ids).
"""

from __future__ import annotations

import rerun as rr

from catabot.bus.messages import RadarSweep
from catabot.run.recorded import RecordedRun
from catabot.run.recorded_camera import labelled_frames
from catabot.world.world import MountedSensor
from services.viewer.logger import RunLogger


def replay(run: RecordedRun, rec: rr.RecordingStream) -> RunLogger:
    logger = RunLogger(rec, run.world, scripts=False)  # run.mcap holds the scripted ones
    states = run.states()
    for i in range(len(states)):
        logger.states(states.batch(i, run.dt_ns))
    for sensor in run.world.sensors:
        _sensor(run, logger, sensor)
    for body in run.world.vessels:
        for stamp_ns, cmd in run.thrust(body.id):
            logger.thrust(body.id, stamp_ns, cmd.thrust)
        twists = list(run.twist(body.id))
        logger.setpoints(
            body.id, [t for t, _ in twists], [(c.surge, c.yaw_rate) for _, c in twists]
        )
    metrics = run.metrics()
    if metrics is not None and len(states):
        logger.metrics(int(states.stamp_ns[-1]), metrics)
    return logger


def _sensor(run: RecordedRun, logger: RunLogger, sensor: MountedSensor) -> None:
    kind, stream = sensor.config.type, run.stream(sensor)
    if kind == "lidar":
        for scan in run.lidar_scans(sensor):
            logger.lidar(sensor, scan)
    elif kind == "radar":
        for sweep in run.messages(stream, RadarSweep):
            logger.radar(sensor, sweep)
    elif kind == "imu":
        logger.imu(sensor, list(run.imu(sensor)))
    elif kind == "camera":
        _camera(run, logger, sensor)


def _camera(run: RecordedRun, logger: RunLogger, sensor: MountedSensor) -> None:
    """Every colour image of the MCAP, with its classes and boxes where dataset/ saved the
    frame (`recording.dataset_rate_hz` may save fewer); frames only dataset/ has, from it."""
    labelled = {f.stamp_ns: f for f in labelled_frames(run.folder, sensor)}
    shown = set()
    for stamp_ns, color in run.images(sensor, "color"):
        frame = labelled.get(stamp_ns)
        segmentation = frame.read("class") if frame is not None else None
        logger.camera(sensor, stamp_ns, color, segmentation, frame.boxes if frame else None)
        shown.add(stamp_ns)
    for stamp_ns, frame in labelled.items():
        if stamp_ns not in shown:
            logger.camera(sensor, stamp_ns, frame.read("color"), frame.read("class"), frame.boxes)
