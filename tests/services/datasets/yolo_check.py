"""A strict reader of an Ultralytics YOLO detection dataset, in place of
`ultralytics.data.utils.check_det_dataset` (Ultralytics needs torch, gigabytes).

It applies Ultralytics' own rules, stricter where Ultralytics only warns: data.yaml with an
existing absolute `path`, `train` and `val` folders under it, `names` indexed 0..nc-1 and
`nc` equal to their count; labels found by Ultralytics' path rule (`/images/` -> `/labels/`,
suffix `.txt`) for every image, each line `class x y w h` with an integer class below nc,
coordinates in [0, 1], sizes > 0 and no duplicate line; every image readable. Returns the
number of images and boxes per split.
"""

from __future__ import annotations

from pathlib import Path

import yaml
from PIL import Image

IMAGE_SUFFIXES = {".bmp", ".jpg", ".jpeg", ".png", ".tif", ".tiff", ".webp"}


class YoloDatasetError(AssertionError):
    pass


def label_path(image: Path) -> Path:
    """Ultralytics' img2label_paths: the last `/images/` becomes `/labels/`, suffix .txt."""
    text = str(image)
    head, sep, tail = text.rpartition("/images/")
    if not sep:
        raise YoloDatasetError(f"{image}: not under an images/ folder")
    return Path(head + "/labels/" + tail).with_suffix(".txt")


def _names(data: dict[str, object]) -> dict[int, str]:
    names = data.get("names")
    if isinstance(names, list):
        names = dict(enumerate(names))
    if not isinstance(names, dict) or sorted(names) != list(range(len(names))):
        raise YoloDatasetError(f"names must be indexed 0..nc-1 (got {names!r})")
    if data.get("nc", len(names)) != len(names):
        raise YoloDatasetError(f"nc {data.get('nc')} != {len(names)} names")
    return {int(k): str(v) for k, v in names.items()}


def _check_labels(label: Path, nc: int) -> int:
    lines = [line.split() for line in label.read_text().splitlines() if line.strip()]
    for n, cols in enumerate(lines, start=1):
        if len(cols) != 5:
            raise YoloDatasetError(f"{label}:{n}: {len(cols)} columns, not 5")
        if not cols[0].isdigit() or int(cols[0]) >= nc:
            raise YoloDatasetError(f"{label}:{n}: class {cols[0]} not in 0..{nc - 1}")
        x, y, w, h = (float(v) for v in cols[1:])
        if not all(0.0 <= v <= 1.0 for v in (x, y, w, h)) or w <= 0 or h <= 0:
            raise YoloDatasetError(f"{label}:{n}: coordinates out of [0, 1] or empty box")
        if x - w / 2 < -1e-6 or x + w / 2 > 1 + 1e-6 or y - h / 2 < -1e-6 or y + h / 2 > 1 + 1e-6:
            raise YoloDatasetError(f"{label}:{n}: box leaves the image")
    if len({tuple(c) for c in lines}) != len(lines):
        raise YoloDatasetError(f"{label}: duplicate labels")
    return len(lines)


def check_yolo(data_yaml: Path) -> dict[str, tuple[int, int]]:
    data = yaml.safe_load(data_yaml.read_text())
    root = Path(data["path"])
    if not root.is_absolute() or not root.is_dir():
        raise YoloDatasetError(f"path {root} is not an existing absolute folder")
    nc = len(_names(data))
    out = {}
    for split in ("train", "val"):
        folder = root / data[split]
        images = sorted(p for p in folder.glob("*") if p.suffix.lower() in IMAGE_SUFFIXES)
        if not images:
            raise YoloDatasetError(f"{split}: no images in {folder}")
        boxes = 0
        for image in images:
            with Image.open(image) as im:
                im.verify()
            label = label_path(image)
            if not label.is_file():
                raise YoloDatasetError(f"{image}: no label file {label}")
            boxes += _check_labels(label, nc)
        out[split] = (len(images), boxes)
    return out
