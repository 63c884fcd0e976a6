"""The dataset exports' edge cases, on the run test_viz_run.py reads: frames saved without
an output, small boxes left out, the calibration's LiDAR-to-camera projection, and the
segmentation export's class images."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest
from conftest import catabot
from PIL import Image

from tests.services.datasets.yolo_check import check_yolo

pytestmark = pytest.mark.filterwarnings("ignore:__array__ implementation:DeprecationWarning")


@pytest.fixture(scope="module")
def run(viz_run: Path) -> Path:
    return viz_run


def _without(run: Path, tmp: Path, drop: int, output: str = "color") -> Path:
    """A copy of the run whose first `drop` frames were saved with `output` off."""
    copy = tmp / f"off{drop}{output}"
    shutil.copytree(run, copy, ignore=shutil.ignore_patterns("export", "*.rrd", "*.mcap"))
    labels = copy / "dataset" / "ego.cam" / "labels.jsonl"
    records = [json.loads(x) for x in labels.read_text().split()]
    for record in records[:drop]:
        del record["files"][output]
    labels.write_text("".join(json.dumps(r) + "\n" for r in records))
    return copy


def test_frames_without_a_colour_image_are_left_out_and_named(run: Path, tmp_path: Path) -> None:
    """Colour switched off for a while (`catabot set`) made the whole run unexportable."""
    out = tmp_path / "yolo"
    result = catabot("dataset", "export", str(_without(run, tmp_path, 3)), "-f", "yolo",
                     "-o", str(out))  # fmt: skip
    assert result.returncode == 0, result.stderr
    assert (
        "7 images" in result.stdout
        and "left out 3 frames without a colour image (first: ego.cam@" in result.stdout
    )
    assert sum(n for n, _ in check_yolo(out / "data.yaml").values()) == 7
    none = catabot("dataset", "export", str(_without(run, tmp_path, 10)), "-f", "coco",
                   "-o", str(tmp_path / "coco"))  # fmt: skip
    assert (
        none.returncode == 2 and "no labelled frame has a colour or instance image" in none.stderr
    )


def test_coco_leaves_out_frames_without_segmentation(run: Path, tmp_path: Path) -> None:
    """Segmentation switched off by the settings timeline failed the whole COCO export, and
    with it the run that asked for it (`recording.export`)."""
    out = tmp_path / "coco"
    result = catabot("dataset", "export", str(_without(run, tmp_path, 4, "instance")), "-f",
                     "coco", "-o", str(out))  # fmt: skip
    assert result.returncode == 0, result.stderr
    assert "left out 4 frames without a colour or instance image" in result.stdout
    docs = [json.loads((out / "annotations" / f"instances_{s}.json").read_text())
            for s in ("train", "val")]  # fmt: skip
    assert sum(len(d["images"]) for d in docs) == 6


def test_small_boxes_are_left_out_on_request(run: Path, tmp_path: Path) -> None:
    every, fewer = tmp_path / "every", tmp_path / "fewer"
    kept = catabot("dataset", "export", str(run), "-f", "yolo", "-o", str(every))
    big = catabot("dataset", "export", str(run), "-f", "yolo", "-o", str(fewer),
                  "--min-box-px", "2", "--val-fraction", "0")  # fmt: skip
    assert kept.returncode == big.returncode == 0, kept.stderr + big.stderr
    boxes = [_boxes(every, s) for s in ("train", "val")]
    wide = [b for rows in boxes for b in rows if min(b[0] * 160, b[1] * 120) >= 2 - 1e-6]
    assert 0 < len(wide) < sum(map(len, boxes)), boxes
    assert len(_boxes(fewer, "train")) == len(wide) and _boxes(fewer, "val") == []
    assert f"left out {sum(map(len, boxes)) - len(wide)} boxes under 2 px" in big.stdout
    assert "(--val-fraction 0: the val set is empty)" in big.stdout


def _boxes(out: Path, subset: str) -> list[tuple[float, float]]:
    """Each YOLO label's (width, height), normalised."""
    lines = [x for f in sorted((out / "labels" / subset).glob("*.txt"))
             for x in f.read_text().splitlines()]  # fmt: skip
    return [(float(x.split()[3]), float(x.split()[4])) for x in lines]


def test_calibration_projects_lidar_points_onto_the_camera_pixels_of_their_body(
    run: Path,
) -> None:
    """dataset/calibration.json: LiDAR points of a body (KITTI export, sensor frame) taken
    through the LiDAR's mount and the camera's, then K, land on that body's instance pixels
    (within a pixel: a point on a silhouette's edge rounds either way)."""
    calib = json.loads((run / "dataset" / "calibration.json").read_text())["sensors"]
    cam, lidar = calib["ego.cam"], calib["ego.lidar"]
    assert cam["vessel"] == lidar["vessel"] == "ego" and cam["width"] == 160
    to_camera = np.linalg.inv(cam["body_from_optical"]) @ np.array(lidar["body_from_sensor"])
    seq = run / "export" / "kitti" / "sequences" / "00"
    times = [round(float(t) * 1e9) for t in (seq / "times.txt").read_text().split()]
    frames = [json.loads(x) for x in (run / "dataset/ego.cam/labels.jsonl").read_text().split()]
    hits = total = 0
    for frame in frames:
        n = times.index(frame["stamp_ns"])  # the camera's ticks are the LiDAR's too
        points = np.fromfile(seq / "velodyne" / f"{n:06d}.bin", "<f4").reshape(-1, 4)[:, :3]
        labels = np.fromfile(seq / "labels" / f"{n:06d}.label", "<u4")
        body = np.isin(labels & 0xFFFF, (3, 4))  # vessels and buoys
        xyz = (to_camera @ np.c_[points[body], np.ones(body.sum())].T)[:3]
        u, v = np.rint((np.array(cam["K"]) @ xyz)[:2] / xyz[2]).astype(int)
        seen = (xyz[2] > 0.5) & (u >= 0) & (u < 160) & (v >= 0) & (v < 120)
        image = Image.open(run / "dataset/ego.cam" / frame["files"]["instance"])
        painted, steps = np.pad(np.asarray(image), 1), (-1, 0, 1)
        near = [painted[v[seen] + 1 + dv, u[seen] + 1 + du] for dv in steps for du in steps]
        hits += int((np.array(near) == (labels[body] >> 16)[seen]).any(axis=0).sum())
        total += int(seen.sum())
    assert total > 10 and hits == total, (hits, total)


def test_segmentation_export_is_the_class_images_split_with_a_legend(run: Path) -> None:
    out = run / "export" / "segmentation"
    legend = json.loads((out / "classes.json").read_text())
    assert legend["classes"] == ["none", "water", "terrain", "vessel", "buoy"]
    assert legend["ignore_index"] == 255 and len(legend["palette"]) == 5
    subsets = ("train", "val")
    names = {s: sorted(p.stem for p in (out / "ann_dir" / s).glob("*.png")) for s in subsets}
    assert names == {s: legend[s] for s in subsets} and sum(map(len, names.values())) == 10
    for subset, stems in names.items():
        for stem in stems:
            tick = stem.rsplit("_", 1)[1]
            ann = np.asarray(Image.open(out / "ann_dir" / subset / f"{stem}.png"))
            painted = np.asarray(Image.open(run / "dataset/ego.cam" / f"{tick}_class.png"))
            assert ann.dtype == np.uint8 and (ann == painted).all()  # the ego is not in view
            image = (out / "img_dir" / subset / f"{stem}.png").read_bytes()
            assert image == (run / "dataset/ego.cam" / f"{tick}_color.png").read_bytes()
