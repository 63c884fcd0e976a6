"""A semantic-segmentation dataset (MMSegmentation's layout) from a run's labelled frames.

    OUT/img_dir/{train,val}/<frame>.png   the colour images, copied byte for byte
    OUT/ann_dir/{train,val}/<frame>.png   8-bit class ids per pixel: 0 none (sky: no surface
                                          hit), 1 water, 2 terrain, 3 vessel, 4 buoy; 255
                                          (IGNORE) the camera's own vessel
    OUT/classes.json                      names, RGB palette, ignore_index, the split

Why: COCO carries only the vessels' and buoys' masks, so a segmentation network (water,
shore, sky) had to read the run's own `dataset/`, with no split and no legend. The camera's
own vessel, its bow in every frame of a low camera, is ignored as Cityscapes ignores its
"ego vehicle" (`--keep-own` paints it a vessel, as the class image does).
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
from PIL import Image

from catabot.bus.messages import LABEL_CLASSES
from catabot.run.recorded import RecordedRun
from catabot.world.label_colors import CLASS_COLORS
from services.datasets.frames import ExportError, ExportOptions, Frame, camera_frames

IGNORE = 255  # MMSegmentation's ignore_index default


def annotation(frame: Frame) -> np.ndarray:
    """The frame's class image, its own vessel's pixels IGNORE (unless kept)."""
    classes, instance = frame.labelled.read("class"), frame.labelled.read("instance")
    if classes is None or instance is None:  # checked for every frame by `camera_frames`
        raise ExportError(f"{frame.name}: no class image (camera output 'segmentation' off)")
    out = np.array(classes, dtype=np.uint8)
    if frame.own:
        out[instance == frame.own] = IGNORE
    return out


def legend(frames: list[Frame]) -> dict[str, object]:
    return {
        "classes": list(LABEL_CLASSES),
        "palette": [list(CLASS_COLORS[name]) for name in LABEL_CLASSES],
        "ignore_index": IGNORE,
        "none": "sky: no surface hit within the camera's range",
        "train": sorted(f.name for f in frames if f.subset == "train"),
        "val": sorted(f.name for f in frames if f.subset == "val"),
    }


def export(run: RecordedRun, out: Path, options: ExportOptions) -> str:
    frames, note = camera_frames(run, options, needs=("color", "class", "instance"), boxes=False)
    for subset in ("train", "val"):
        (out / "img_dir" / subset).mkdir(parents=True, exist_ok=True)
        (out / "ann_dir" / subset).mkdir(parents=True, exist_ok=True)
    ignored = 0
    for frame in frames:
        shutil.copyfile(frame.color, out / "img_dir" / frame.subset / f"{frame.name}.png")
        ann = annotation(frame)
        ignored += int(np.count_nonzero(ann == IGNORE))
        Image.fromarray(ann).save(out / "ann_dir" / frame.subset / f"{frame.name}.png",
                                  compress_level=3)  # fmt: skip
    (out / "classes.json").write_text(json.dumps(legend(frames), indent=1) + "\n")
    val = sum(f.subset == "val" for f in frames)
    own = f", {ignored} pixels of the cameras' own vessels ignored ({IGNORE})" if ignored else ""
    return f"{len(frames)} images ({len(frames) - val} train, {val} val){own}{note}"
