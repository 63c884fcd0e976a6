"""A COCO instance-segmentation dataset from a run's labelled frames.

    OUT/{train,val}/<frame>.png                 the colour images, copied byte for byte
    OUT/annotations/instances_{train,val}.json  images, annotations, categories

Each annotation is one visible body in one frame: `bbox` [x, y, width, height] (the visible
box, which holds every pixel of the mask), `segmentation` its instance mask as compressed RLE
(rle.py), `area` the mask's pixel count, `iscrowd` 0, plus CataBot's `instance` (the body's
World row + 1), `truncated` and `occluded` flags and `visible` (the share of the body's
silhouette seen). Category ids are the segmentation class
ids (3 vessel, 4 buoy), so a mask painted with its category id gives back the class image.
pycocotools' `COCO(...)`, detectron2 and torchvision's CocoDetection read it as it is.
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path
from typing import Any

import numpy as np

from catabot.bus.messages import LABEL_CLASSES
from catabot.run.recorded import RecordedRun
from catabot.run.recorded_camera import BOX_CLASSES
from services.datasets import rle
from services.datasets.frames import ExportError, ExportOptions, Frame, camera_frames

CATEGORIES = [
    {"id": LABEL_CLASSES.index(name), "name": name, "supercategory": "object"}
    for name in BOX_CLASSES
]


def frame_annotations(frame: Frame, image_id: int, first_id: int) -> list[dict[str, Any]]:
    """One annotation per box of the frame, masks from its instance image."""
    instance = frame.labelled.read("instance")
    if instance is None:  # checked for every frame by `camera_frames`
        raise ExportError(f"{frame.name}: no instance image (camera output 'segmentation' off)")
    out = []
    for k, (row, flags) in enumerate(zip(frame.boxes, frame.flags, strict=True)):
        mask = instance == int(row[0])
        x0, y0, x1, y1 = (int(v) for v in row[2:6])
        out.append({
            "id": first_id + k,
            "image_id": image_id,
            "category_id": int(row[1]),
            "bbox": [x0, y0, x1 - x0, y1 - y0],
            "area": int(np.count_nonzero(mask)),
            "segmentation": rle.encode(mask),
            "iscrowd": 0,
            "instance": int(row[0]),
            "truncated": bool(flags[0]),
            "occluded": bool(flags[1]),
            "visible": int(flags[2]) / 100,
        })  # fmt: skip
    return out


def document(run: RecordedRun, frames: list[Frame], subset: str) -> dict[str, Any]:
    images: list[dict[str, Any]] = []
    annos: list[dict[str, Any]] = []
    for image_id, frame in enumerate(frames, start=1):
        width, height = frame.labelled.size
        images.append({
            "id": image_id, "file_name": f"{frame.name}.png", "width": width, "height": height,
            "camera": frame.camera, "tick": frame.labelled.tick,
            "stamp_ns": frame.labelled.stamp_ns,
        })  # fmt: skip
        annos += frame_annotations(frame, image_id, len(annos) + 1)
    return {
        "info": {"description": f"CataBot world {run.world.scenario.name} ({subset})",
                 "version": "1", "contributor": "CataBot"},
        "licenses": [],
        "images": images,
        "annotations": annos,
        "categories": CATEGORIES,
    }  # fmt: skip


def export(run: RecordedRun, out: Path, options: ExportOptions) -> str:
    frames, note = camera_frames(run, options, needs=("color", "instance"))
    (out / "annotations").mkdir(parents=True, exist_ok=True)
    counts = []
    for subset in ("train", "val"):
        mine = [f for f in frames if f.subset == subset]
        (out / subset).mkdir(parents=True, exist_ok=True)
        for frame in mine:
            shutil.copyfile(frame.color, out / subset / f"{frame.name}.png")
        doc = document(run, mine, subset)
        text = json.dumps(doc, separators=(",", ":"))
        (out / "annotations" / f"instances_{subset}.json").write_text(text)
        counts.append(f"{subset} {len(mine)} images / {len(doc['annotations'])} annotations")
    return ", ".join(counts) + note
