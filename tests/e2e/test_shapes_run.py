"""Vessel shapes through `catabot run`: a LiDAR's recorded scans of a WAM-V 8 m ahead hold
points on its pontoons and frame, none in the gap between its hulls (as its hull box they
were mostly there), and water seen through that gap."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import open3d as o3d
from conftest import basic_scenario, catabot, only_run_dir, scenario_file

from catabot.bus.messages import CLASS_VESSEL, CLASS_WATER
from catabot.run.recorded import RecordedRun
from catabot.world import rotations
from catabot.world.shapes import ShapeMesh


def _distance_to(mesh: ShapeMesh, points: np.ndarray) -> np.ndarray:
    scene = o3d.t.geometry.RaycastingScene()
    scene.add_triangles(
        o3d.core.Tensor(mesh.vertices.astype(np.float32)),
        o3d.core.Tensor(mesh.triangles.astype(np.uint32)),
    )
    query = o3d.core.Tensor(points.astype(np.float32))
    return scene.compute_distance(query).numpy().astype(np.float64)


def test_a_recorded_scan_of_a_catamaran_ahead_has_no_points_between_its_hulls(
    tmp_path: Path, out: Path
) -> None:
    data = basic_scenario("shapes", duration_s=0.5)
    data["vessels"][0].pop("script")
    data["vessels"][0]["sensors"] = [{"name": "lidar", "type": "lidar", "rate_hz": 10.0}]
    data["vessels"].append({"id": "wamv", "model": "wamv", "pose": {"x_m": 8.0, "y_m": 0.0}})
    result = catabot("run", str(scenario_file(tmp_path, data)), "--out", str(out), "--quiet")
    assert result.returncode == 0, result.stderr
    run = RecordedRun(only_run_dir(out))
    world, track = run.world, run.states()
    ego, wamv = world.body("ego"), world.body("wamv")
    mesh = world.shapes["wamv"]
    assert mesh is not None
    scans = list(run.lidar_scans(world.sensors[0]))
    assert len(scans) == 5
    start = world.start_states()  # what tick 0 is cast at; then the state stamped alike
    for scan in scans:
        k = np.flatnonzero(track.stamp_ns == scan.stamp_ns)
        pos = track.position[k[0]] if k.size else start.position
        quat = track.orientation[k[0]] if k.size else start.orientation
        rot = rotations.normalised_matrices(quat[[ego.row, wamv.row]])
        assert rot is not None
        own, its = rot
        mount = np.array([0.0, 0.0, 1.0])  # the LiDAR's default mount
        world_xyz = (scan.points.astype(np.float64) + mount) @ own.T + pos[ego.row]
        body = (world_xyz - pos[wamv.row]) @ its  # into the WAM-V's frame
        on_it = (scan.cls == CLASS_VESSEL) & (scan.instance == wamv.instance)
        assert on_it.sum() > 40
        assert _distance_to(mesh, body[on_it]).max() < 0.05  # on its shape (LiDAR noise 1 cm)
        gap = (np.abs(body[:, 1]) < 0.75) & (np.abs(body[:, 0]) < 2.4) & (body[:, 2] < 0.7)
        assert not (gap & on_it).any()
        assert (gap & (scan.cls == CLASS_WATER)).sum() > 10  # the beams pass between the hulls
