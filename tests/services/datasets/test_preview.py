"""`catabot dataset preview`: the labels drawn where they are, kept boxes in their class
colour and left-out ones grey, each mask's edge traced."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from catabot.config.load import load_scenario
from catabot.run.recorded_camera import LabelledFrame
from services.datasets.cli import main
from services.datasets.frames import ExportOptions, Frame
from services.datasets.preview import COLOURS, LEFT_OUT, drawn


def frame(tmp_path: Path, *, min_visible: float) -> Frame:
    Image.fromarray(np.zeros((40, 60, 3), np.uint8)).save(tmp_path / "c.png")
    instance = np.zeros((40, 60), np.uint16)
    instance[10:20, 10:30] = 5  # a boat, fully seen: its hull and, at its left, a cabin
    instance[10:15, 20:30] = 0
    instance[25:30, 40:50] = 7  # a buoy, mostly hidden
    Image.fromarray(instance).save(tmp_path / "i.png")
    objects = [
        {"instance": 5, "class": "vessel", "box": [10, 10, 30, 20], "visible": 1.0},
        {"instance": 7, "class": "buoy", "box": [40, 25, 50, 30], "visible": 0.2},
    ]
    for o in objects:
        o |= {"truncated": False, "occluded": o["visible"] < 1}
    record = {"tick": 0, "stamp_ns": 0, "width": 60, "height": 40, "objects": objects,
              "files": {"color": "c.png", "instance": "i.png"}}  # fmt: skip
    labelled = LabelledFrame(tmp_path, record)
    options = ExportOptions(min_visible=min_visible)
    return Frame("ego.cam_00000000", "ego.cam", labelled, "train", 0, options)


def test_kept_boxes_are_in_their_class_colour_and_left_out_ones_grey(tmp_path: Path) -> None:
    pixels = np.asarray(drawn(frame(tmp_path, min_visible=0.5)))
    assert tuple(pixels[15, 10]) == COLOURS["vessel"]  # the boat's box, left edge
    assert tuple(pixels[27, 40]) == LEFT_OUT  # the buoy's: under 50 % visible
    assert tuple(pixels[35, 5]) == (0, 0, 0)  # nothing drawn where nothing is
    kept = np.asarray(drawn(frame(tmp_path, min_visible=0.0)))
    assert tuple(kept[27, 40]) == COLOURS["buoy"]


def test_each_mask_edge_is_traced_inside_the_body(tmp_path: Path) -> None:
    pixels = np.asarray(drawn(frame(tmp_path, min_visible=0.0)))
    assert tuple(pixels[15, 25]) == COLOURS["vessel"]  # the hull's top, right of the cabin
    assert tuple(pixels[12, 25]) == (0, 0, 0)  # above it: in the box, not the boat
    assert tuple(pixels[17, 15]) == (0, 0, 0)  # inside the mask: the image's own


def test_a_label_that_would_cover_a_larger_boxs_is_left_out(tmp_path: Path) -> None:
    """Distant boats' names ran together into one unreadable strip (a trial user)."""
    Image.fromarray(np.zeros((40, 120, 3), np.uint8)).save(tmp_path / "c.png")
    objects = [
        {"instance": 5, "class": "vessel", "box": [10, 20, 40, 30], "visible": 1.0},
        {"instance": 7, "class": "buoy", "box": [44, 24, 48, 28], "visible": 1.0},
    ]
    record = {"tick": 0, "stamp_ns": 0, "width": 120, "height": 40,
              "objects": [o | {"truncated": False, "occluded": False} for o in objects],
              "files": {"color": "c.png"}}  # fmt: skip
    labelled = LabelledFrame(tmp_path, record)
    options = ExportOptions(min_visible=0.0)
    pixels = np.asarray(drawn(Frame("c_0", "c", labelled, "train", 0, options)))
    red, green = (pixels[:19, :, c].astype(float) for c in (0, 1))  # above the boxes: names
    inked = red > 60  # text is smoothed: its colour by hue, red (vessel) or yellow (buoy)
    assert (inked & (green < 0.4 * red)).any()  # the larger box's name
    assert not (inked & (green > 0.6 * red)).any()  # not the buoy's, over it
    assert (pixels[24:28, 44] == COLOURS["buoy"]).all()  # its box is drawn all the same


def test_a_run_without_a_camera_is_refused_in_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    run = tmp_path / "run"
    run.mkdir()
    (run / "scenario.json").write_text(load_scenario().model_dump_json())
    assert main(["preview", str(run), "-o", str(tmp_path / "look")]) == 2
    err = capsys.readouterr().err
    assert err.startswith("catabot dataset preview: ") and "no labelled camera frames" in err
    assert not (tmp_path / "look").exists()
