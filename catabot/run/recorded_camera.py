"""The labelled camera frames of a run folder: `dataset/<vessel>.<camera>/` read back.

The recorder writes each saved frame's outputs as files and one `labels.jsonl` line
(services/recorder/dataset.py; DESIGN.md §8 "Cameras"): this module is the reading side,
shared by the dataset export and the viewer's replay (the MCAP holds colour and depth only).
"""

from __future__ import annotations

import json
import logging
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray
from PIL import Image

from catabot.bus.messages import LABEL_CLASSES
from catabot.run.recorded import RunFolderError
from catabot.world.world import MountedSensor

log = logging.getLogger("catabot.run.recorded_camera")

BOX_CLASSES = ("vessel", "buoy")
"""The classes that have boxes (the camera boxes bodies only), in detection-index order."""


@dataclass(frozen=True)
class LabelledFrame:
    """One saved frame: its `labels.jsonl` record and the folder its files are in."""

    folder: Path
    record: dict[str, Any]

    @property
    def tick(self) -> int:
        return int(self.record["tick"])

    @property
    def stamp_ns(self) -> int:
        return int(self.record["stamp_ns"])

    @property
    def size(self) -> tuple[int, int]:
        """(width, height) in pixels."""
        return int(self.record["width"]), int(self.record["height"])

    def path(self, output: str) -> Path | None:
        """The file of an output (`color`, `depth`, `depth_m`, `normals`, `class`,
        `instance`), None if that output was off."""
        name = self.record.get("files", {}).get(output)
        return self.folder / name if name else None

    def read(self, output: str) -> NDArray[Any] | None:
        """An output's pixels (PNG) or array (`.npy`), None if it was off."""
        path = self.path(output)
        if path is None:
            return None
        if path.suffix == ".npy":
            return np.asarray(np.load(path, allow_pickle=False))
        with Image.open(path) as image:
            return np.asarray(image)

    @cached_property
    def boxes(self) -> NDArray[np.float64]:
        """(K, 6) rows [instance, class id, x0, y0, x1, y1) as the camera's `boxes`."""
        rows = [[o["instance"], class_id(o["class"]), *o["box"]] for o in self.record["objects"]]
        return np.array(rows, dtype=np.float64).reshape(len(rows), 6)

    @cached_property
    def flags(self) -> NDArray[np.uint8]:
        """(K, 3) [truncated, occluded, visible %] as the camera's `box_flags` (a run
        recorded before the visible share was labelled: 100)."""
        rows = [[o["truncated"], o["occluded"], round(100 * o.get("visible", 1.0))]
                for o in self.record["objects"]]  # fmt: skip
        return np.array(rows, dtype=np.uint8).reshape(len(rows), 3)


def class_id(name: str) -> int:
    """A class name of labels.jsonl as its id (an unknown class was written as its id)."""
    return LABEL_CLASSES.index(name) if name in LABEL_CLASSES else int(name)


def camera_folder(run: Path, sensor: MountedSensor) -> Path:
    return run / "dataset" / f"{sensor.vessel}.{sensor.config.name}"


def labelled_frames(run: Path, sensor: MountedSensor) -> list[LabelledFrame]:
    """Every saved frame of one camera, in tick order; none if the dataset was not recorded."""
    folder = camera_folder(run, sensor)
    labels = folder / "labels.jsonl"
    if not labels.is_file():
        return []
    frames, text = [], labels.read_text()
    lines = text.splitlines()
    for n, line in enumerate(lines, start=1):
        try:
            frames.append(LabelledFrame(folder, json.loads(line)))
        except json.JSONDecodeError:
            if n == len(lines) > 1 and not text.endswith("\n"):  # a run killed mid-line
                log.warning("%s: its last line is cut off (the run was killed?); the %d whole "
                            "frames before it are read", labels, len(frames))  # fmt: skip
                break
            raise RunFolderError(f"{labels}:{n}: not a JSON line") from None
    return sorted(frames, key=lambda f: f.tick)


def cameras(run: Path, sensors: tuple[MountedSensor, ...]) -> list[MountedSensor]:
    """The cameras of a world whose labelled frames are in the run folder."""
    return [
        s
        for s in sensors
        if s.config.type == "camera" and (camera_folder(run, s) / "labels.jsonl").is_file()
    ]
