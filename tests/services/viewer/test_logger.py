"""The viewer's logger: bus messages into rerun entities on `sim_time`, read back from .rrd."""

from __future__ import annotations

import dataclasses
import json
import math
from pathlib import Path
from typing import Any

import numpy as np
import pyarrow as pa
import rerun as rr

from catabot.bus import codec
from catabot.bus.messages import BodyStates, LidarScan, RadarSweep
from catabot.config.load import parse_scenario
from catabot.config.vessel import load_vessel_model
from catabot.world import rotations
from catabot.world.world import World
from services.viewer import palette
from services.viewer.logger import RunLogger
from services.viewer.static import body_groups


def _world() -> World:
    sensors = [
        {"name": "lidar", "type": "lidar", "rate_hz": 10.0},
        {"name": "radar", "type": "radar", "rate_hz": 10.0},
    ]
    return World.resolve(parse_scenario({
        "seed": 2, "vessels": [{"id": "ego", "pose": {"x_m": 0, "y_m": 0}, "sensors": sensors}],
        "buoys": [{"id": "b1", "x_m": 20.0, "y_m": 0.0}],
        "traffic": {"count": 1, "behaviour_mix": {"circle": 1.0}},
    }))  # fmt: skip


def _record(path: Path, log: Any) -> dict[str, list[pa.RecordBatch]]:
    world = _world()
    rec = rr.RecordingStream("test", recording_id="t", send_properties=False)
    rec.save(path)
    log(RunLogger(rec, world), world)
    rec.flush()
    rec.disconnect()
    out: dict[str, list[pa.RecordBatch]] = {}
    for chunk in rr.chunk.RrdReader(path).stream():
        out.setdefault(chunk.entity_path, []).append(chunk.to_record_batch())
    return out


def _column(batches: list[pa.RecordBatch], suffix: str) -> list[Any]:
    values = []
    for batch in batches:
        names = [n for n in batch.schema.names if n.endswith(suffix)]
        values += batch.column(names[0]).to_pylist() if names else []
    return values


def _decoded_states(world: World, tick: int) -> BodyStates:
    """A batch as it arrives from the bus: arrays are views into the payload at odd offsets."""
    n = len(world.bodies)
    pos = np.arange(3.0 * n).reshape(n, 3)
    quat = np.tile([0.0, 0.0, math.sin(0.25), math.cos(0.25)], (n, 1))
    vel = np.tile([3.0, 4.0, 0.0], (n, 1))
    msg = BodyStates(tick, (tick + 1) * 10_000_000, world.body_ids, pos, quat, vel, vel, vel, vel)
    return codec.decode(codec.encode(msg), BodyStates)


def test_states_become_shape_instances_poses_and_series(tmp_path: Path) -> None:
    """Each model's shape once (static) per colour, its bodies as instances posed a tick."""

    def log(logger: RunLogger, world: World) -> None:
        for tick in range(30):
            logger.states(_decoded_states(world, tick))

    got = _record(tmp_path / "s.rrd", log)
    world = _world()
    for entity, row in (("vessel-catabot", 0), ("boat-monohull", 1), ("buoy-buoy", 2)):
        batches = got[f"/world/bodies/{entity}"]
        poses = _column(batches, "InstancePoses3D:translations")
        assert len(poses) == 30 and poses[-1] == [[3.0 * row, 3.0 * row + 1, 3.0 * row + 2]]
        quat = _column(batches, "InstancePoses3D:quaternions")[-1][0]
        assert np.allclose(quat, [0.0, 0.0, math.sin(0.25), math.cos(0.25)])
        vertices = np.array(_column(batches, "Mesh3D:vertex_positions")[0])
        mesh = world.shapes[world.bodies[row].model_ref]
        assert mesh is not None and len(vertices) == 3 * len(mesh.triangles)  # flat shaded
        assert np.allclose(vertices.min(axis=0), mesh.lo, atol=1e-6)  # the shape, not a box
        assert np.allclose(vertices.max(axis=0), mesh.hi, atol=1e-6)
    assert len(_column(got["/world/vessels/ego"], ":translation")) == 30
    assert _column(got["/series/speed/ego"], ":scalars")[0] == [5.0]  # |(3, 4)| m/s
    heading = _column(got["/series/heading/ego"], ":scalars")[0][0]
    assert math.isclose(heading, 90.0 - math.degrees(0.5))  # yaw 0.5 rad, compass degrees
    assert len(_column(got["/world/trails"], ":positions")) == 2  # every 0.2 s: t = 0.01, 0.21


def test_radar_echoes_drawn_north_up_on_the_minimap(tmp_path: Path) -> None:
    intensity = np.zeros((1, 100), np.uint8)
    intensity[0, 49] = 200  # one echo at 99-100 m, straight ahead
    sweep = RadarSweep(
        0, 0, 0.0, 0.0, math.pi / 2, 200.0, 1, intensity, np.full(1, 99.0, np.float32)
    )

    got = _record(tmp_path / "r.rrd", lambda logger, world: logger.radar(world.sensors[1], sweep))
    ((x, y),) = _column(got["/minimap/ego.radar/echoes"], ":positions")[0]
    assert abs(x) < 1e-3 and math.isclose(y, -99.0)  # heading north: up, screen y points down


def test_lidar_rain_returns_in_magenta(tmp_path: Path) -> None:
    n = 6
    power = np.geomspace(1e-6, 1e-2, n).astype(np.float32)
    scan = LidarScan(
        10, 100_000_000, np.ones((n, 3), np.float32), power,
        np.zeros(n, np.uint16), np.zeros(n, np.uint8), np.zeros(n, np.int32),
        np.array([False, True, False, False, True, False]), np.empty((0, 0), np.float32),
    )  # fmt: skip
    got = _record(tmp_path / "l.rrd", lambda logger, world: logger.lidar(world.sensors[0], scan))
    colors = _column(got["/world/vessels/ego/lidar"], ":colors")[0]
    magenta = int.from_bytes(bytes([*palette.RAIN, 255]), "big")
    assert [c == magenta for c in colors] == scan.is_rain.tolist()
    assert _column(got["/series/lidar/ego.lidar"], ":scalars")[0] == [6.0, 2.0]


def test_terrain_colours_tell_sea_from_land() -> None:
    colors = palette.terrain_colors(np.array([-10.0, -0.1, 0.1, 20.0]), -10.0, 20.0)
    sea, land = colors[:2].astype(int), colors[2:].astype(int)
    assert (sea[:, 2] > sea[:, 1]).all() and (land[:, 1] >= land[:, 2]).all()


def test_a_model_without_a_shape_is_drawn_as_its_hull_box(tmp_path: Path) -> None:
    model = load_vessel_model("catabot").model_dump(mode="json") | {"shape": None}
    (tmp_path / "plain.json").write_text(json.dumps(model))
    world = World.resolve(parse_scenario({
        "seed": 2, "vessels": [{"id": "ego", "model": str(tmp_path / "plain.json")},
                               {"id": "cat", "pose": {"x_m": 30.0, "y_m": 0.0}}],
    }))  # fmt: skip
    groups = {g.path: g for g in body_groups(world)}
    assert set(groups) == {"world/bodies/vessel-plain", "world/bodies/vessel-catabot"}
    box, shape = groups["world/bodies/vessel-plain"], groups["world/bodies/vessel-catabot"]
    lo, hi = load_vessel_model("catabot").hull_box()
    assert box.rows.tolist() == [0] and shape.rows.tolist() == [1]
    assert len(box.mesh.triangles) == 12 and len(np.unique(box.mesh.vertices, axis=0)) == 8
    assert np.allclose(box.mesh.lo, lo) and np.allclose(box.mesh.hi, hi)
    assert len(shape.mesh.triangles) > 12


def test_twist_set_points_are_step_lines_with_their_values(tmp_path: Path) -> None:
    """A navigator's set-points (and the traffic's) were missing from run.rrd: only a
    script's were drawn."""

    def log(logger: RunLogger, _world: World) -> None:
        logger.setpoints("ego", [0, 100_000_000], [(1.0, 0.1), (1.5, -0.2)])
        logger.setpoints("ego", [], [])  # a vessel never commanded: nothing

    got = _record(tmp_path / "t.rrd", log)
    assert _column(got["/series/setpoint/ego"], ":scalars") == [[1.0, 0.1], [1.5, -0.2]]
    names = _column(got["/series/setpoint/ego"], ":names")
    assert names == [["ego surge [m/s]", "ego yaw rate [rad/s]"]]


def test_the_radar_frame_stays_level_on_a_rolling_hull(tmp_path: Path) -> None:
    """Its echoes hang below it: a static identity turn tilted them with the hull."""
    tilted = rotations.from_rpy(math.radians(15.0), math.radians(-5.0), 0.5)

    def log(logger: RunLogger, world: World) -> None:
        states = _decoded_states(world, 0)
        quat = np.tile(tilted, (len(world.bodies), 1))
        logger.states(dataclasses.replace(states, orientation=quat))

    batches = _record(tmp_path / "t.rrd", log)["/world/vessels/ego/radar"]
    ((turn,),) = [q for q in _column(batches, ":quaternion") if q]
    level = rotations.matrix(tilted) @ rotations.matrix(turn)  # type: ignore[operator]
    assert np.allclose(level, rotations.rpy(0.0, 0.0, math.degrees(0.5)), atol=1e-6)
    assert _column(batches, ":translation")[-1] == [[0.0, 0.0, 3.0]]  # the default antenna
