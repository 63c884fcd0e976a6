"""A YOLO detection dataset in the Ultralytics layout, from a run's labelled frames.

    OUT/data.yaml                 path, train, val, nc, names (0 vessel, 1 buoy)
    OUT/images/{train,val}/<frame>.png    the colour images, copied byte for byte
    OUT/labels/{train,val}/<frame>.txt    one `class x_centre y_centre width height` line
                                          per box, normalised to [0, 1]; none: empty file

`ultralytics.data.utils.check_det_dataset("OUT/data.yaml")` accepts it and training reads it
as it is. Classes are the ones with boxes (`BOX_CLASSES`), indexed from 0 as YOLO needs;
the segmentation ids (3 vessel, 4 buoy) are kept in COCO's category ids instead.
"""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np

from catabot.bus.messages import LABEL_CLASSES
from catabot.run.recorded import RecordedRun
from catabot.run.recorded_camera import BOX_CLASSES
from services.datasets.frames import ExportError, ExportOptions, Frame, camera_frames

YOLO_INDEX = {LABEL_CLASSES.index(name): i for i, name in enumerate(BOX_CLASSES)}


def label_lines(frame: Frame) -> str:
    """The frame's label file: one normalised xywh line per box, in the camera's box order."""
    width, height = frame.labelled.size
    boxes = frame.boxes
    unknown = sorted({int(c) for c in boxes[:, 1]} - set(YOLO_INDEX))
    if unknown:
        raise ExportError(f"{frame.name}: boxes of classes {unknown} have no YOLO index")
    x0, y0, x1, y1 = boxes[:, 2], boxes[:, 3], boxes[:, 4], boxes[:, 5]
    xywh = np.stack([(x0 + x1) / 2 / width, (y0 + y1) / 2 / height,
                     (x1 - x0) / width, (y1 - y0) / height], axis=1)  # fmt: skip
    return "".join(
        f"{YOLO_INDEX[int(c)]} {x:.6f} {y:.6f} {w:.6f} {h:.6f}\n"
        for c, (x, y, w, h) in zip(boxes[:, 1], xywh.tolist(), strict=True)
    )


def data_yaml(out: Path, run: RecordedRun) -> str:
    names = "".join(f"  {i}: {name}\n" for i, name in enumerate(BOX_CLASSES))
    return (
        f"# CataBot world {run.world.scenario.name}: YOLO detection dataset (Ultralytics "
        "layout); path: this folder, absolute as Ultralytics wants it (edit it after a move)\n"
        f"path: {out.resolve()}\ntrain: images/train\nval: images/val\n"
        f"nc: {len(BOX_CLASSES)}\nnames:\n{names}"
    )


def export(run: RecordedRun, out: Path, options: ExportOptions) -> str:
    frames, note = camera_frames(run, options)
    for subset in ("train", "val"):
        (out / "images" / subset).mkdir(parents=True, exist_ok=True)
        (out / "labels" / subset).mkdir(parents=True, exist_ok=True)
    for frame in frames:
        shutil.copyfile(frame.color, out / "images" / frame.subset / f"{frame.name}.png")
        (out / "labels" / frame.subset / f"{frame.name}.txt").write_text(label_lines(frame))
    (out / "data.yaml").write_text(data_yaml(out, run))
    val = sum(f.subset == "val" for f in frames)
    boxes = sum(len(f.boxes) for f in frames)
    return f"{len(frames)} images ({len(frames) - val} train, {val} val), {boxes} boxes{note}"
