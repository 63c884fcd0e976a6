"""`catabot dataset preview`: every labelled frame with its labels drawn on it, as PNGs.

Why: labels are checked by looking. A perception engineer drew the boxes and masks onto the
images with a script of their own before trusting an export. Each frame's colour image gets
the outline of every body's mask (its instance pixels' edge, in its class colour), the box
an export with the same options keeps (solid, named `class instance visible%`) and the boxes
those options leave out (thin grey: too small, too hidden, the camera's own vessel).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from numpy.typing import NDArray
from PIL import Image, ImageDraw

from catabot.bus.messages import LABEL_CLASSES
from catabot.run.recorded import RecordedRun
from services.datasets.frames import ExportOptions, Frame, camera_frames

COLOURS = {"vessel": (255, 64, 64), "buoy": (255, 200, 0)}  # the rest: white
LEFT_OUT = (150, 150, 150)


def export(run: RecordedRun, out: Path, options: ExportOptions) -> str:
    frames, note = camera_frames(run, options)
    for frame in frames:
        drawn(frame).save(out / f"{frame.name}.png")
    boxes = sum(len(f.boxes) for f in frames)
    return f"{len(frames)} frames drawn, {boxes} boxes kept{note}"


def drawn(frame: Frame) -> Image.Image:
    with Image.open(frame.color) as source:
        image = source.convert("RGB")
    instance = frame.labelled.read("instance")
    if instance is not None:
        image = _outlined(image, instance, frame)
    pen = ImageDraw.Draw(image)
    boxes, kept, flags = frame.labelled.boxes, frame.kept, frame.labelled.flags
    for row, keep in zip(boxes, kept, strict=True):
        _box(pen, row, kept=bool(keep))
    taken: list[tuple[float, float, float, float]] = []
    rows = np.flatnonzero(kept)
    area = (boxes[rows, 4] - boxes[rows, 2]) * (boxes[rows, 5] - boxes[rows, 3])
    for k in rows[np.argsort(-area, kind="stable")]:  # the largest box names itself first
        _label(pen, boxes[k], flags[k], taken)
    return image


def _box(pen: ImageDraw.ImageDraw, row: NDArray[np.float64], *, kept: bool) -> None:
    colour = COLOURS.get(_class_name(int(row[1])), (255, 255, 255)) if kept else LEFT_OUT
    x0, y0, x1, y1 = (float(v) for v in row[2:6])
    pen.rectangle((x0, y0, x1 - 1, y1 - 1), outline=colour, width=2 if kept else 1)


def _label(pen: ImageDraw.ImageDraw, row: NDArray[np.float64], flags: NDArray[np.uint8],
           taken: list[tuple[float, float, float, float]]) -> None:  # fmt: skip
    """A kept box's name above it, unless it would cover a larger box's name (distant boats'
    names ran together into one unreadable strip, a trial user found)."""
    name = _class_name(int(row[1]))
    text = f"{name} {int(row[0])} {int(flags[2])}%"
    at = (float(row[2]), max(float(row[3]) - 11, 0.0))
    x0, y0, x1, y1 = pen.textbbox(at, text, stroke_width=1)
    if any(x0 < b[2] and b[0] < x1 and y0 < b[3] and b[1] < y1 for b in taken):
        return
    taken.append((x0, y0, x1, y1))  # outlined in black: a buoy's yellow on a pale sky
    pen.text(at, text, fill=COLOURS.get(name, (255, 255, 255)), stroke_width=1, stroke_fill=0)


def _outlined(image: Image.Image, instance: NDArray[np.generic], frame: Frame) -> Image.Image:
    """Each body's mask edge (a pixel of it beside another instance or none) in its class
    colour (white for a body without a box)."""
    ids = np.asarray(instance, dtype=np.int64)
    edge = np.zeros(ids.shape, dtype=bool)
    edge[1:] |= ids[1:] != ids[:-1]
    edge[:-1] |= ids[:-1] != ids[1:]
    edge[:, 1:] |= ids[:, 1:] != ids[:, :-1]
    edge[:, :-1] |= ids[:, :-1] != ids[:, 1:]
    edge &= ids > 0
    colour = np.full((int(ids.max(initial=0)) + 1, 3), 255, dtype=np.uint8)  # by instance
    for row in frame.labelled.boxes:
        if 0 < row[0] < len(colour):
            colour[int(row[0])] = COLOURS.get(_class_name(int(row[1])), (255, 255, 255))
    pixels = np.array(image)
    pixels[edge] = colour[ids[edge]]
    return Image.fromarray(pixels)


def _class_name(class_id: int) -> str:
    return LABEL_CLASSES[class_id] if 0 <= class_id < len(LABEL_CLASSES) else str(class_id)
