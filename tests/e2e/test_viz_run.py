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

import numpy as np
import pytest
import rerun as rr
import yaml
from conftest import VIZ_SECONDS, catabot, files_of, in_process
from PIL import Image
from pycocotools.coco import COCO

from services.recorder.mcap_read import read_mcap_messages
from tests.services.datasets.yolo_check import check_yolo

pytestmark = pytest.mark.filterwarnings("ignore:__array__ implementation:DeprecationWarning")


@pytest.fixture(scope="module")
def run(viz_run: Path) -> Path:
    return viz_run


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
    assert ticks == round(VIZ_SECONDS * 100) + 1 and timelines == {"sim_time"}  # + the start
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
    for boat in ("boat_000", "boat_001"):  # the traffic's set-points (only a script's before)
        assert rows[f"/series/setpoint/{boat}"] == topics[f"/{boat}/cmd_vel"] > 0
    assert rows["/series/thrust/ego"] == topics["/ego/thrust"] == 1  # the script's, not twice
    assert (
        rows["/world/trails"] == round(VIZ_SECONDS / 0.2) + 1 and rows["/metrics"] == 1
    )  # from t = 0
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
            code, out, err = in_process(filled, capsys)
    assert code == 2, out + err
    assert message in err and "Traceback" not in out + err
