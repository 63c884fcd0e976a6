"""Which boxes of a frame an export keeps: not those below `--min-box-px`, and not those of
the camera's own vessel (its bow in view) unless asked; the segmentation export ignores its
pixels alike."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from PIL import Image

from catabot.run.recorded_camera import LabelledFrame
from services.datasets.frames import ExportOptions, Frame, _note
from services.datasets.segmentation import IGNORE, annotation


def _frame(*, own: int, min_box_px: int = 0, min_visible: float = 0.0) -> Frame:
    objects = [  # the ego (instance 1) at the bottom edge, a boat, a distant buoy
        {"instance": 1, "class": "vessel", "box": [202, 452, 438, 480]},
        {"instance": 3, "class": "vessel", "box": [300, 200, 340, 230]},
        {"instance": 4, "class": "buoy", "box": [100, 240, 103, 245]},
    ]
    for o, visible in zip(objects, (0.6, 0.25, 1.0), strict=True):
        o |= {"truncated": False, "occluded": visible < 1, "visible": visible}
    record = {"tick": 0, "stamp_ns": 0, "width": 640, "height": 480, "objects": objects}
    options = ExportOptions(min_box_px=min_box_px, min_visible=min_visible)
    return Frame("ego.cam_00000000", "ego.cam", LabelledFrame(Path("."), record), "train",
                 own, options)  # fmt: skip


def test_the_cameras_own_vessel_is_left_out_and_said() -> None:
    frame = _frame(own=1)
    assert frame.boxes[:, 0].tolist() == [3, 4]
    assert "left out 1 boxes of the cameras' own vessels (--keep-own keeps them)" in _note(
        [frame], [], "colour image", ExportOptions()
    )


def test_keep_own_keeps_it_and_small_boxes_are_counted_once() -> None:
    assert _frame(own=0).boxes[:, 0].tolist() == [1, 3, 4]  # --keep-own: own is 0
    frame = _frame(own=1, min_box_px=5)
    assert frame.boxes[:, 0].tolist() == [3]
    note = _note([frame], [], "colour image", ExportOptions(min_box_px=5))
    assert "left out 1 boxes under 5 px" in note and "left out 1 boxes of the cameras'" in note


def test_boxes_of_bodies_barely_visible_are_left_out_when_asked() -> None:
    """A boat seen as a sliver past another (10 % visible) taught a detector a sliver."""
    assert _frame(own=0, min_visible=0.0).boxes[:, 0].tolist() == [1, 3, 4]
    frame = _frame(own=1, min_visible=0.3)
    assert frame.boxes[:, 0].tolist() == [4]
    note = _note([frame], [], "colour image", ExportOptions(min_visible=0.3))
    assert "left out 1 boxes of bodies under 30% visible (--min-visible)" in note
    assert "left out 1 boxes of the cameras' own" in note  # the ego's, counted once
    assert _frame(own=0, min_visible=0.25).boxes[:, 0].tolist() == [1, 3, 4]  # at the line


def test_segmentation_ignores_the_cameras_own_vessel_unless_kept(tmp_path: Path) -> None:
    classes = np.array([[1, 1, 3], [3, 3, 4]], np.uint8)  # water, then the ego's bow and a buoy
    instance = np.array([[0, 0, 5], [1, 1, 7]], np.uint16)  # 1: the ego
    Image.fromarray(classes).save(tmp_path / "c.png")
    Image.fromarray(instance).save(tmp_path / "i.png")
    record = {"tick": 0, "stamp_ns": 0, "width": 3, "height": 2, "objects": [],
              "files": {"class": "c.png", "instance": "i.png"}}  # fmt: skip
    labelled = LabelledFrame(tmp_path, record)
    own = annotation(Frame("ego.cam_00000000", "ego.cam", labelled, "train", 1))
    assert own.tolist() == [[1, 1, 3], [IGNORE, IGNORE, 4]]
    kept = annotation(Frame("ego.cam_00000000", "ego.cam", labelled, "train", 0))
    assert (kept == classes).all()
