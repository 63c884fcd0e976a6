"""One recorded run, then everything made from it: run.rrd (read back with rerun's reader),
`catabot view RUN --save`, the YOLO, COCO and KITTI exports, `catabot plot`, and the refusals.

The run asks for `recording.rerun` and `recording.export`, so `catabot run` itself makes
run.rrd and export/<format>/ after the lockstep; the other tools are run on its folder.
"""

from __future__ import annotations

import json
import shutil
import socket
from collections import Counter
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import rerun as rr
import yaml
from conftest import basic_scenario, catabot, files_of, only_run_dir, scenario_file
from PIL import Image
from pycocotools.coco import COCO

from catabot.run.cli import main
from services.recorder.mcap_read import read_mcap_messages
from tests.services.datasets.yolo_check import check_yolo

SECONDS = 2.0
pytestmark = pytest.mark.filterwarnings("ignore:__array__ implementation:DeprecationWarning")


def _scenario() -> dict[str, Any]:
    data = basic_scenario("viz", duration_s=SECONDS)
    data["vessels"][0]["pose"] = {"x_m": 0.0, "y_m": 0.0}
    data["vessels"][0]["sensors"] = [
        {"name": "cam", "type": "camera", "rate_hz": 5.0, "params": {"width": 160, "height": 120}},
        {"name": "lidar", "type": "lidar", "rate_hz": 10.0,
         "params": {"channels": 16, "columns": 256}},
        {"name": "radar", "type": "radar", "rate_hz": 20.0, "params": {"rotation_period_s": 0.5}},
        {"name": "imu", "type": "imu", "rate_hz": 50.0},
    ]  # fmt: skip
    data["vessels"].append({"id": "other", "pose": {"x_m": 30.0, "y_m": 1.0}})
    data["buoys"] = [{"id": "b1", "x_m": 25.0, "y_m": -6.0}]
    data["traffic"] = {"count": 2, "behaviour_mix": {"circle": 1.0}}
    data["rain"] = {"rate_mm_h": 20.0}
    data["recording"] = {"rerun": True, "export": ["yolo", "coco", "kitti", "segmentation"]}
    return data


@pytest.fixture(scope="module")
def run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    tmp = tmp_path_factory.mktemp("viz")
    out = tmp / "runs"
    out.mkdir()
    result = catabot("run", str(scenario_file(tmp, _scenario())), "--out", str(out), "--quiet")
    assert result.returncode == 0, result.stdout + result.stderr
    run = only_run_dir(out)
    (tmp / "console.txt").write_text(result.stdout)
    return run


def _rows(rrd: Path) -> tuple[Counter[str], set[str], set[str]]:
    """Rows on `sim_time` by entity path, the static entities, every timeline seen."""
    rows: Counter[str] = Counter()
    static, timelines = set(), set()
    for chunk in rr.chunk.RrdReader(rrd).stream():
        timelines.update(chunk.timeline_names)
        if chunk.is_static:
            static.add(chunk.entity_path)
        else:
            rows[chunk.entity_path] += chunk.num_rows
    return rows, static, timelines


def _topic_counts(run: Path, name: str = "run.mcap") -> Counter[str]:
    return Counter(m.topic for m in read_mcap_messages(run / name))


def test_run_rrd_holds_every_stream_on_sim_time(run: Path) -> None:
    rows, static, timelines = _rows(run / "run.rrd")
    topics = _topic_counts(run)
    ticks = topics["/tf"]
    assert ticks == round(SECONDS * 100) + 1 and timelines == {"sim_time"}  # + the start
    bodies = [
        "/world/bodies/vessel-catabot",
        "/world/bodies/boat-monohull",
        "/world/bodies/buoy-buoy",
    ]
    assert all(rows[b] == ticks for b in bodies) and rows["/world/vessels/ego"] == ticks
    assert rows["/series/speed/ego"] == ticks and rows["/series/speed/other"] == ticks
    assert rows["/world/vessels/ego/lidar"] == topics["/ego/lidar/points"] == 20
    assert rows["/world/vessels/ego/cam/color"] == topics["/ego/cam/image_raw"] == 10
    assert rows["/world/vessels/ego/cam/segmentation"] == rows["/world/vessels/ego/cam/boxes"] == 10
    sweeps = _topic_counts(run, "run.extra.mcap")["/sensor/ego/radar"]
    assert rows["/minimap/ego.radar/echoes"] == sweeps == topics["/ego/radar/points"] == 40
    assert rows["/series/imu_accel/ego.imu"] == topics["/ego/imu/imu"] == 100
    assert rows["/world/trails"] == round(SECONDS / 0.2) + 1 and rows["/metrics"] == 1  # from t = 0
    assert {*bodies, "/world/water", "/world/vessels/ego/cam"} <= static  # the shapes, once
    (entry,) = rr.chunk.RrdReader(run / "run.rrd").recordings()
    assert entry.recording_id == run.name  # two runs' files open side by side, not merged


def test_view_replays_the_run_into_the_same_rows(run: Path, tmp_path: Path) -> None:
    result = catabot("view", str(run), "--save", str(tmp_path / "again.rrd"))
    assert result.returncode == 0, result.stderr
    assert _rows(tmp_path / "again.rrd") == _rows(run / "run.rrd")


def test_yolo_export_passes_a_strict_check(run: Path) -> None:
    found = check_yolo(run / "export" / "yolo" / "data.yaml")
    labels = [json.loads(x) for x in (run / "dataset/ego.cam/labels.jsonl").read_text().split()]
    assert sum(n for n, _ in found.values()) == len(labels) == 10
    assert sum(b for _, b in found.values()) == sum(len(x["objects"]) for x in labels) > 0


def test_the_console_says_what_each_export_wrote(run: Path) -> None:
    """It said nothing: the summary (and a left-out note) was only in log/export-*.log."""
    console = (run.parent.parent / "console.txt").read_text()
    for fmt, what in (("yolo", "images"), ("coco", "annotations"), ("kitti", "scans")):
        assert f"  export-{fmt}: {fmt} dataset in {run / 'export' / fmt}: " in console
        assert what in console.split(f"export-{fmt}: ")[1].splitlines()[0]


def test_coco_masks_match_the_boxes_and_the_class_images(run: Path) -> None:
    seen = 0
    for subset in ("train", "val"):
        coco = COCO(str(run / "export" / "coco" / "annotations" / f"instances_{subset}.json"))
        for image in coco.loadImgs(coco.getImgIds()):
            assert (run / "export" / "coco" / subset / image["file_name"]).is_file()
            classes = np.asarray(Image.open(run / f"dataset/ego.cam/{image['tick']:08d}_class.png"))
            painted = np.zeros_like(classes)
            for ann in coco.loadAnns(coco.getAnnIds(imgIds=image["id"])):
                mask = coco.annToMask(ann).astype(bool)
                x, y, w, h = ann["bbox"]
                ys, xs = np.nonzero(mask)
                assert mask.sum() == ann["area"] > 0
                assert xs.min() >= x and xs.max() < x + w and ys.min() >= y and ys.max() < y + h
                painted[mask] = ann["category_id"]
                seen += 1
            bodies = np.isin(classes, (3, 4))
            assert (painted[bodies] == classes[bodies]).all() and not painted[~bodies].any()
    labels = [json.loads(x) for x in (run / "dataset/ego.cam/labels.jsonl").read_text().split()]
    assert seen == sum(len(x["objects"]) for x in labels)


def test_kitti_labels_one_per_point_with_rain_as_its_class(run: Path) -> None:
    seq = run / "export" / "kitti" / "sequences" / "00"
    clouds = [
        m.decoded for m in read_mcap_messages(run / "run.mcap") if m.topic == "/ego/lidar/points"
    ]
    assert len(sorted((seq / "velodyne").glob("*.bin"))) == len(clouds) == 20
    assert len((seq / "poses.txt").read_text().splitlines()) == len(clouds)
    per_class = np.zeros(6)
    for n, cloud in enumerate(clouds):
        points = np.fromfile(seq / "velodyne" / f"{n:06d}.bin", dtype="<f4").reshape(-1, 4)
        labels = np.fromfile(seq / "labels" / f"{n:06d}.label", dtype="<u4")
        assert len(points) == len(labels) == cloud.width
        rain = np.frombuffer(bytes(cloud.data), np.uint8).reshape(-1, cloud.point_step)[:, 19]
        assert ((labels & 0xFFFF) == 5).sum() == rain.sum() > 0
        assert set(np.unique(labels & 0xFFFF).tolist()) <= {0, 1, 2, 3, 4, 5}
        per_class += np.bincount(labels & 0xFFFF, minlength=6)
    config = yaml.safe_load((run / "export" / "kitti" / "catabot.yaml").read_text())
    same = {i: i for i in range(6)}  # what SemanticKITTI's visualize.py and trainers read
    assert config["learning_map"] == config["learning_map_inv"] == same
    assert config["learning_ignore"] == {i: i == 0 for i in range(6)}
    assert config["labels"][5] == "rain" and config["color_map"][5] == [255, 0, 255]
    content = [config["content"][i] for i in range(6)]
    np.testing.assert_allclose(content, per_class / per_class.sum(), atol=1e-8)
    assert config["split"]["train"] == [0] and config["sequences"] == {"00": "ego.lidar"}


def test_plot_writes_figures_and_a_report(run: Path, tmp_path: Path) -> None:
    result = catabot("plot", str(run), "-o", str(tmp_path / "plots"))
    assert result.returncode == 0, result.stderr
    pngs = sorted((tmp_path / "plots").glob("*.png"))
    names = {p.stem for p in pngs}
    figures = "trajectories trajectories_own speed_heading thrust imu lidar_rain metrics"
    assert names == set(figures.split())  # _own: the traffic spreads the first view
    for png in pngs:
        with Image.open(png) as image:
            pixels = np.asarray(image.convert("L"))
        assert pixels.std() > 5, f"{png.name} is blank"
    report = (tmp_path / "plots" / "report.html").read_text()
    assert all(f'src="{p.name}"' in report for p in pngs) and "Closest approach" in report
    assert "<th>goal, nearest, contacts, thrust</th>" in report and "collisions 0" in report
    again = catabot("plot", str(run), "-o", str(tmp_path / "again"))
    assert again.returncode == 0
    assert files_of(tmp_path / "plots", ("*",)) == files_of(tmp_path / "again", ("*",))
    both = catabot("plot", str(run), str(run), "-o", str(tmp_path / "cmp"))  # runs compared
    assert both.returncode == 0 and "2 runs compared in" in both.stdout, both.stderr
    page = (tmp_path / "cmp" / "compare.html").read_text()
    assert page.count(f"<td>{run.name}</td><td>ego</td>") == 2 and "compare_trajectories" in page


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (("view", "{tmp}/nowhere", "--save", "{tmp}/x.rrd"), "no such run folder"),
        (("plot", "{tmp}/nowhere"), "no such run folder"),
        (("plot", "{run}/scenario.json"), "scenario.json: a file, not a run folder"),
        (("plot", "{run}", "{run}", "-o", "{run}/scenario.json"), "is a file; give a folder"),
        (("dataset", "export", "{tmp}/nowhere", "-f", "yolo", "-o", "{tmp}/o"), "no such run"),
        (("dataset", "export", "{run}", "-f", "voc", "-o", "{tmp}/o"), "invalid choice: 'voc'"),
        (("dataset", "export", "{run}", "-f", "yolo", "-o", "{run}"), "is not an empty folder"),
        (("dataset", "export", "{nocam}", "-f", "coco", "-o", "{tmp}/o"), "no labelled camera"),
        (("view", "{tmp}"), "not a run folder"),
        (("plot", "{unticked}"), "the run recorded no tick (it was interrupted before its first;"),
        (("view", "{run}", "--save", "{tmp}/no/x.rrd"), "does not exist"),
        (("view", "{run}", "--web", "--no-hold", "--web-port", "{taken}"), "Address already"),
    ],
)
def test_refusals_exit_2_with_one_clear_line(
    run: Path,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    args: tuple[str, ...],
    message: str,
) -> None:
    """In this process but for the web viewer's (a server) and the first (a shell's view):
    twelve start-ups of the tools cost CI's 15 minutes 20 s."""
    nocam = tmp_path / "nocam"
    nocam.mkdir()
    scenario = json.loads((run / "scenario.json").read_text())
    scenario["vessels"][0]["sensors"] = [s for s in scenario["vessels"][0]["sensors"]
                                         if s["type"] != "camera"]  # fmt: skip
    scenario["recording"]["export"] = []
    (nocam / "scenario.json").write_text(json.dumps(scenario))
    unticked = tmp_path / "unticked"  # stopped before its first tick: plot named a cut-off run.mcap
    (unticked / "log").mkdir(parents=True)
    shutil.copy(nocam / "scenario.json", unticked)
    (unticked / "log" / "run.json").write_text('{"ticks": 0, "reason": "interrupted"}')
    with socket.socket() as taken:  # a port in use: a second web viewer met rerun's 9090
        taken.bind(("0.0.0.0", 0))
        taken.listen()
        port = taken.getsockname()[1]
        folders = {"run": run, "nocam": nocam, "unticked": unticked}
        filled = [a.format(tmp=tmp_path, taken=port, **folders) for a in args]
        if "--web" in filled or (message == "no such run folder" and filled[0] == "view"):
            result = catabot(*filled)
            code, out, err = result.returncode, result.stdout, result.stderr
        else:
            code, out, err = _in_process(filled, capsys)
    assert code == 2, out + err
    assert message in err and "Traceback" not in out + err


def _in_process(args: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[int, str, str]:
    """main's exit code (argparse's own refusals exit) and what it printed."""
    try:
        code = main(args)
    except SystemExit as exit_:
        code = exit_.code if isinstance(exit_.code, int) else 1
    said = capsys.readouterr()
    return code, said.out, said.err


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
