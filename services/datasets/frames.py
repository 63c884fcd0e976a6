"""The frames an export is made of: every labelled frame of every camera, named once.

A frame's name, `<vessel>.<camera>_<tick>` (8 digits), is its file stem in every format, so
one image has the same name in the YOLO and COCO exports and in the run's own `dataset/`.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from catabot.errors import CataBotError
from catabot.run.recorded import RecordedRun
from catabot.run.recorded_camera import LabelledFrame, cameras, labelled_frames
from services.datasets.split import empty_set, split

NAMES = {"color": "colour", "class": "class", "instance": "instance"}  # as said


class ExportError(CataBotError, ValueError):
    """A run that cannot give the asked-for dataset (no camera, no LiDAR, no labels)."""


VAL_FRACTION = 0.2  # the share of frames for validation when none is asked


@dataclass(frozen=True)
class ExportOptions:
    """How a run becomes a dataset: the train/val split (split.py), the smallest box kept,
    in pixels of width and height (distant buoys of 1-2 px teach a detector noise), and
    whether the boxes of a camera's own vessel are kept: a camera mounted low sees its own
    bow in every frame, a box a detector would learn to find there (Cityscapes' "ego
    vehicle", left out of training the same way)."""

    val_fraction: float = VAL_FRACTION
    block_s: float | None = None
    min_box_px: int = 0
    keep_own: bool = False
    min_visible: float = 0.0  # the smallest visible share of a body kept as a box (0..1)


@dataclass(frozen=True)
class Frame:
    name: str
    camera: str  # `<vessel>.<camera>`
    labelled: LabelledFrame
    subset: str  # "train" or "val"
    own: int = 0  # the instance id of the camera's own vessel (0: its boxes are kept)
    options: ExportOptions = ExportOptions()  # which boxes are kept (min_box_px, min_visible)

    @property
    def color(self) -> Path:
        path = self.labelled.path("color")
        if path is None:  # checked for every frame by `camera_frames`
            raise ExportError(f"{self.name}: no colour image")
        return path

    @cached_property
    def small(self) -> NDArray[np.bool_]:
        """The boxes narrower or lower than `min_box_px`, in the camera's box order."""
        boxes = self.labelled.boxes
        size = np.minimum(boxes[:, 4] - boxes[:, 2], boxes[:, 5] - boxes[:, 3])
        return np.asarray(size < self.options.min_box_px)

    @cached_property
    def mine(self) -> NDArray[np.bool_]:
        """The boxes of the camera's own vessel (none when `own` is 0)."""
        return np.asarray((self.labelled.boxes[:, 0] == self.own) & (self.own > 0))

    @cached_property
    def hidden(self) -> NDArray[np.bool_]:
        """The boxes of bodies less visible than `min_visible` (a sliver past another boat:
        its box says little of the boat)."""
        return np.asarray(self.labelled.flags[:, 2] < round(100 * self.options.min_visible))

    @property
    def kept(self) -> NDArray[np.bool_]:
        return ~self.small & ~self.mine & ~self.hidden

    @property
    def boxes(self) -> NDArray[np.float64]:
        return self.labelled.boxes[self.kept]

    @property
    def flags(self) -> NDArray[np.uint8]:
        return self.labelled.flags[self.kept]


def camera_frames(
    run: RecordedRun,
    options: ExportOptions,
    *,
    needs: tuple[str, ...] = ("color",),
    boxes: bool = True,
) -> tuple[list[Frame], str]:
    """Every labelled frame with the outputs the format `needs`, split into train and val,
    and a note on the frames left out for want of one (a camera's output switched off for a
    while: the settings timeline, `catabot set`) and the boxes below the size kept."""
    found = cameras(run.folder, run.world.sensors)
    if not found:
        raise ExportError(
            f"{run.folder}: no labelled camera frames (the run needs a camera and "
            "recording.dataset: true; dataset/<vessel>.<camera>/labels.jsonl holds them)"
        )
    own = {s.vessel: 0 if options.keep_own else run.world.body(s.vessel).instance for s in found}
    pairs = [
        (f"{s.vessel}.{s.config.name}", f, own[s.vessel])
        for s in found
        for f in labelled_frames(run.folder, s)
    ]
    whole = [all(f.path(n) is not None for n in needs) for _, f, _ in pairs]
    without = [f"{cam}@{f.tick}" for (cam, f, _), ok in zip(pairs, whole, strict=True) if not ok]
    pairs = [pair for pair, ok in zip(pairs, whole, strict=True) if ok]
    what = " or ".join(NAMES[n] for n in needs) + " image"
    if not pairs:
        raise ExportError(f"{run.folder}: no labelled frame has a {what} (the cameras' outputs "
                          f"were off: outputs.{', outputs.'.join(needs)})")  # fmt: skip
    subsets = split([f.stamp_ns for _, f, _ in pairs], seed=run.world.scenario.seed,
                    val_fraction=options.val_fraction, block_s=options.block_s)  # fmt: skip
    frames = [
        Frame(f"{cam}_{f.tick:08d}", cam, f, subset, mine, options)
        for (cam, f, mine), subset in zip(pairs, subsets, strict=True)
    ]
    note = _note(frames, without, what, options if boxes else None)
    return frames, note + empty_set(subsets, options.val_fraction)


def _note(frames: list[Frame], without: list[str], what: str, options: ExportOptions | None) -> str:
    """What was left out: frames, and (`options` given: a format of boxes) boxes."""
    note = ""
    if without:
        note += f"; left out {len(without)} frames without a {what} (first: {without[0]})"
    if options is None:
        return note
    small = sum(int((f.small & ~f.mine).sum()) for f in frames)
    if small:
        note += f"; left out {small} boxes under {options.min_box_px} px (--min-box-px)"
    hidden = sum(int((f.hidden & ~f.small & ~f.mine).sum()) for f in frames)
    if hidden:
        note += (f"; left out {hidden} boxes of bodies under {options.min_visible:.0%} "
                 "visible (--min-visible)")  # fmt: skip
    mine = sum(int(f.mine.sum()) for f in frames)
    if mine:
        note += f"; left out {mine} boxes of the cameras' own vessels (--keep-own keeps them)"
    return note
