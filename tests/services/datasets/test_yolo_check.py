"""The strict YOLO reader used in place of Ultralytics' checker refuses what it should."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from tests.services.datasets.yolo_check import YoloDatasetError, check_yolo


def _dataset(root: Path, label: str) -> Path:
    for split in ("train", "val"):
        (root / "images" / split).mkdir(parents=True)
        (root / "labels" / split).mkdir(parents=True)
        Image.fromarray(np.zeros((8, 8, 3), np.uint8)).save(root / "images" / split / "a.png")
        (root / "labels" / split / "a.txt").write_text(label)
    yaml = root / "data.yaml"
    yaml.write_text(
        f"path: {root}\ntrain: images/train\nval: images/val\nnc: 2\nnames:\n  0: a\n  1: b\n"
    )
    return yaml


def test_a_good_dataset_passes(tmp_path: Path) -> None:
    assert check_yolo(_dataset(tmp_path, "1 0.5 0.5 0.2 0.2\n")) == {"train": (1, 1), "val": (1, 1)}


@pytest.mark.parametrize(
    "label",
    ["2 0.5 0.5 0.2 0.2\n", "0 0.5 0.5 0.2\n", "0 1.2 0.5 0.2 0.2\n", "0 0.95 0.5 0.2 0.2\n",
     "0 0.5 0.5 0 0.2\n", "0 0.5 0.5 0.2 0.2\n0 0.5 0.5 0.2 0.2\n"],
)  # fmt: skip
def test_bad_labels_are_refused(tmp_path: Path, label: str) -> None:
    with pytest.raises(YoloDatasetError):
        check_yolo(_dataset(tmp_path, label))


def test_a_missing_label_file_is_refused(tmp_path: Path) -> None:
    yaml = _dataset(tmp_path, "")
    (tmp_path / "labels" / "val" / "a.txt").unlink()
    with pytest.raises(YoloDatasetError, match="no label file"):
        check_yolo(yaml)
