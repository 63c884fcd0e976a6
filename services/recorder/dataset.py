"""`dataset/` in the run folder: labelled camera frames and radar PPI images as PNG files.

Layout (one folder per sensor, `<vessel>.<sensor>`):
- cameras: `<tick>_color.png` (RGB), `<tick>_depth.png` (16-bit grey, millimetres along the
  optical axis; 0 = no return or beyond 65.535 m) and `<tick>_depth.npy` (float32 metres, inf =
  no return: the exact values), `<tick>_normals.png` (RGB = (n + 1) / 2 in
  the optical frame z forward, x right, y down), `<tick>_class.png` (8-bit class ids of
  `LABEL_CLASSES`: 0 none, 1 water, 2 terrain, 3 vessel, 4 buoy) and `<tick>_instance.png`
  (16-bit, a body's row + 1), for the outputs that are on, plus one `labels.jsonl` line per
  frame with its boxes, each naming its body;
  every frame, or with `recording.dataset_rate_hz` one in every n (config/rates.py);
- radars: `ppi_<tick>.png`, the north-up PPI (services/recorder/ppi.py) once per antenna turn;
- with `recording.dataset` and a camera or a LiDAR, or with PPIs, `calibration.json`: every
  sensor's mount and each camera's K (calibration.py): a radar-only run's mounts were in
  `/tf_static` alone, and a LiDAR-only run (the KITTI export's scans) had none.
PNGs are written with fixed settings and no time chunk, so the same run gives the same bytes.
`catabot.run.recorded_camera` reads this layout back (dataset export, replay).
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
from PIL import Image

from catabot.bus.messages import LABEL_CLASSES, CameraFrame, Message, RadarSweep
from catabot.config.rates import dataset_period
from catabot.config.sensors import RadarParams
from catabot.world.world import World
from services.recorder.calibration import write_calibration
from services.recorder.ppi import Ppi

PNG_LEVEL = 3  # zlib level: fast; fixed, so the same pixels give the same bytes


def save_png(path: Path, pixels: np.ndarray) -> None:
    """One PNG; uint16 grey becomes 16-bit, uint8 (H, W[, 3]) 8-bit grey or RGB."""
    Image.fromarray(np.ascontiguousarray(pixels)).save(path, format="PNG", compress_level=PNG_LEVEL)


def depth_mm(depth: np.ndarray) -> np.ndarray:
    """Depth (m, inf = none) as uint16 millimetres, 0 where there is no or no storable return."""
    mm = np.where(np.isfinite(depth), np.rint(depth * 1000.0), 0.0)
    return np.where(mm <= 65535, mm, 0).astype(np.uint16)


def labels(frame: CameraFrame, files: dict[str, str], *, bodies: dict[int, str]) -> dict[str, Any]:
    """The labels.jsonl record of one frame; `bodies`: body ids by instance (`instances`), so
    each object names its body (a user had to rebuild the order of the rows, and the
    traffic's waypoint buoys are in no scenario file)."""
    objects = [
        {
            "instance": int(row[0]),
            "body": bodies.get(int(row[0])),
            "class": LABEL_CLASSES[int(row[1])]
            if int(row[1]) < len(LABEL_CLASSES)
            else str(int(row[1])),
            "box": [int(v) for v in row[2:6]],
            "truncated": bool(flag[0]),
            "occluded": bool(flag[1]),
            "visible": int(flag[2]) / 100,
        }
        for row, flag in zip(frame.boxes, frame.box_flags, strict=True)
    ]
    return {
        "tick": frame.tick,
        "stamp_ns": frame.stamp_ns,
        "width": frame.width,
        "height": frame.height,
        "files": files,
        "objects": objects,
    }


def instances(world: World) -> dict[int, str]:
    """Each body's id by its label instance (catabot/world/world.py: Body.instance)."""
    return {b.instance: b.id for b in world.bodies}


def save_npy(path: Path, values: np.ndarray) -> None:
    """One `.npy` (its header holds only dtype, order and shape: same array, same bytes)."""
    np.save(path, np.ascontiguousarray(values), allow_pickle=False)


class Dataset:
    """Writes the dataset of every camera and radar of a scenario under `root`."""

    def __init__(self, root: Path, world: World) -> None:
        self.root = root
        self.bodies = instances(world)
        recording = world.scenario.recording
        self.cameras = recording.dataset
        self.every = 1 if recording.dataset_rate_hz is None else dataset_period(world.scenario)
        self.camera_period = {  # ticks between two frames of each camera stream
            world.keys.relative(s.key): s.period for s in world.sensors if s.config.type == "camera"
        }
        self.radar: dict[str, tuple[RadarParams, int]] = {
            world.keys.relative(s.key): (s.params, s.config.period_ns)
            for s in world.sensors
            if s.config.type == "radar" and recording.ppi
        }
        self._ppi: dict[str, Ppi] = {}
        imaging = any(s.config.type in ("camera", "lidar") for s in world.sensors)
        if (self.cameras and imaging) or self.radar:  # frames, scans to export, or PPIs
            write_calibration(root, world)

    def folder(self, stream: str) -> Path:
        parts = stream.strip("/").split("/")
        path = self.root / ".".join(parts[1:])
        path.mkdir(parents=True, exist_ok=True)
        return path

    def write(self, stream: str, msg: Message) -> None:
        if isinstance(msg, CameraFrame) and self.cameras and self._due(stream, msg.tick):
            self._camera(stream, msg)
        elif isinstance(msg, RadarSweep) and stream in self.radar:
            self._radar(stream, msg)

    def _due(self, stream: str, tick: int) -> bool:
        """Whether a frame is saved: it is the first at or after a dataset period's start
        (a boundary lies in (tick - camera period, tick]), so any rate works with any camera."""
        period = self.camera_period.get(stream, 1)
        return tick // self.every > (tick - period) // self.every

    def _camera(self, stream: str, frame: CameraFrame) -> None:
        folder, stem = self.folder(stream), f"{frame.tick:08d}"
        images = {
            "color": frame.color,
            "depth": depth_mm(frame.depth) if frame.depth.size else frame.depth,
            "normals": np.rint((frame.normals.astype(np.float32) / 127.0 + 1.0) * 127.5)
            .clip(0, 255)
            .astype(np.uint8),
            "class": frame.segmentation,
            "instance": frame.instance.astype(np.uint16),
        }
        files = {}
        for name, pixels in images.items():
            if pixels.size:
                files[name] = f"{stem}_{name}.png"
                save_png(folder / files[name], pixels)
        if frame.depth.size:
            files["depth_m"] = f"{stem}_depth.npy"
            save_npy(folder / files["depth_m"], frame.depth.astype(np.float32, copy=False))
        with open(folder / "labels.jsonl", "a", encoding="utf-8") as out:
            record = labels(frame, files, bodies=self.bodies)
            out.write(json.dumps(record, separators=(",", ":")) + "\n")

    def _radar(self, stream: str, sweep: RadarSweep) -> None:
        """Paint the sweep; save the PPI when this sweep ends an antenna turn (the next one
        starts a new turn), so a run of whole turns writes one image per turn."""
        p, period_ns = self.radar[stream]
        ppi = self._ppi.get(stream)
        if ppi is None:
            step = 2 * np.pi / max(1, round(720.0 / p.beam_width_deg))  # as radar.py spaces beams
            ppi = Ppi(size_px=p.ppi_size_px, range_m=p.range_m, fade_s=p.fade, beam_step_rad=step)
            self._ppi[stream] = ppi
        ppi.add(sweep)
        turn_ns = round(p.rotation_period_s * 1e9)
        if (sweep.stamp_ns + period_ns) // turn_ns > sweep.stamp_ns // turn_ns:
            save_png(self.folder(stream) / f"ppi_{sweep.tick:08d}.png", ppi.render(sweep.stamp_ns))
