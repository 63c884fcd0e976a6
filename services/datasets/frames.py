"""The frames an export is made of: every labelled frame of every camera, named once.

A frame's name, `<vessel>.<camera>_<tick>` (8 digits), is its file stem in every format, so
one image has the same name in the YOLO and COCO exports and in the run's own `dataset/`.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from catabot.errors import CataBotError
from catabot.run.recorded import RecordedRun
from catabot.run.recorded_camera import LabelledFrame, cameras, labelled_frames
from services.datasets.split import split


class ExportError(CataBotError, ValueError):
    """A run that cannot give the asked-for dataset (no camera, no LiDAR, no labels)."""


@dataclass(frozen=True)
class Frame:
    name: str
    camera: str  # `<vessel>.<camera>`
    labelled: LabelledFrame
    subset: str  # "train" or "val"

    @property
    def color(self) -> Path:
        path = self.labelled.path("color")
        if path is None:  # checked for every frame by `camera_frames`
            raise ExportError(f"{self.name}: no colour image")
        return path


def camera_frames(
    run: RecordedRun, *, val_fraction: float, block_s: float | None
) -> tuple[list[Frame], str]:
    """Every labelled frame with a colour image, split into train and val, and a note on
    the frames left out for want of one (a camera's colour output switched off for a
    while: `catabot set`), empty when none was."""
    found = cameras(run.folder, run.world.sensors)
    if not found:
        raise ExportError(
            f"{run.folder}: no labelled camera frames (the run needs a camera and "
            "recording.dataset: true; dataset/<vessel>.<camera>/labels.jsonl holds them)"
        )
    pairs = [
        (f"{s.vessel}.{s.config.name}", f) for s in found for f in labelled_frames(run.folder, s)
    ]
    without = [f"{cam}@{f.tick}" for cam, f in pairs if f.path("color") is None]
    pairs = [(cam, f) for cam, f in pairs if f.path("color") is not None]
    if not pairs:
        raise ExportError(f"{run.folder}: no labelled frame has a colour image (the cameras' "
                          "colour output was off: outputs.color)")  # fmt: skip
    note = f"; left out {len(without)} frames without a colour image ({without[:1]}...)"
    subsets = split(
        [f.stamp_ns for _, f in pairs],
        seed=run.world.scenario.seed,
        val_fraction=val_fraction,
        block_s=block_s,
    )
    frames = [
        Frame(f"{cam}_{f.tick:08d}", cam, f, subset)
        for (cam, f), subset in zip(pairs, subsets, strict=True)
    ]
    return frames, (note if without else "")
