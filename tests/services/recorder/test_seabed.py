"""Shore distance (an exact distance transform) and grounding (hull probes below the ground)."""

from __future__ import annotations

import dataclasses
import json
import math
from pathlib import Path

import numpy as np
import pytest

from catabot.bus.messages import BodyStates
from catabot.config.load import parse_scenario
from catabot.world.orders import Orders
from catabot.world.terrain import Terrain
from catabot.world.world import World
from services.recorder.metrics import Metrics
from services.recorder.seabed import Seabed, distance_transform


def _brute(mask: np.ndarray) -> np.ndarray:
    ys, xs = np.nonzero(mask)
    if not len(ys):
        return np.full(mask.shape, np.inf)
    gy, gx = np.mgrid[: mask.shape[0], : mask.shape[1]]
    return np.sqrt(((gy[..., None] - ys) ** 2 + (gx[..., None] - xs) ** 2).min(axis=-1))


@pytest.mark.parametrize("seed", range(12))
def test_distance_transform_is_exact(seed: int) -> None:
    rng = np.random.default_rng(seed)
    shape = tuple(int(v) for v in rng.integers(1, 24, size=2))
    mask = rng.random(shape) < rng.choice([0.0, 0.02, 0.1, 0.5])
    assert np.array_equal(distance_transform(mask), _brute(mask))


def test_stacked_masks_share_the_row_pass() -> None:
    rng = np.random.default_rng(7)
    for shape in ((2, 9, 17), (3, 17, 9)):  # wide grids are transposed first
        masks = rng.random(shape) < 0.05
        masks[-1] = False  # one without any pixel: inf everywhere
        got = distance_transform(masks)
        for k in range(shape[0]):
            assert np.array_equal(got[k], _brute(masks[k]))


def _shore() -> Terrain:
    """1 m pixels, 10 m deep west of x = 40 m, +5 m (land) from there on."""
    z = np.full((30, 50), -10.0)
    z[:, 40:] = 5.0
    return Terrain(z, 1.0)


def _world(terrain: Terrain, xs: list[float]) -> World:
    vessels = [{"id": f"v{k}", "pose": {"x_m": x, "y_m": 5.0 + 5 * k}} for k, x in enumerate(xs)]
    world = World.resolve(parse_scenario({"name": "s", "vessels": vessels}))
    return dataclasses.replace(world, terrain=terrain)


def test_shore_lookup_is_the_terrains_bilinear_rule() -> None:
    terrain = _shore()
    world = _world(terrain, [10.0, 20.0, 30.0, 35.0])
    seabed = Seabed(terrain, world.bodies)
    pos = np.array([[3.2, 4.7, 0.0], [38.9, 20.0, 0.0], [-5.0, 40.0, 0.0], [45.0, 2.0, 0.0]])
    shore, _ = seabed.lookup(pos)
    field = Terrain(distance_transform(terrain.elevation_m >= 0), 1.0)
    assert shore is not None
    np.testing.assert_allclose(shore, field.height(pos[:, 0], pos[:, 1]), atol=1e-12)
    assert shore[0] == pytest.approx(40.5 - 3.2)  # to the first land pixel's centre
    assert shore[3] == 0.0


def test_no_land_no_shore_distance() -> None:
    terrain = Terrain(np.full((10, 10), -20.0), 2.0)
    seabed = Seabed(terrain, _world(terrain, [5.0]).bodies)
    shore, near = seabed.check(np.array([[5.0, 5.0, 0.0]]))
    assert shore is None and not near.any()


def test_skipped_lookups_change_nothing() -> None:
    """`check` looks up only when the slope bound allows a change: along a random walk near
    the bank its running minimum and its grounding candidates are those of every lookup."""
    gy, gx = np.mgrid[0:40, 0:60] + 0.5
    island = 30.0 * np.exp(-((gx - 30) ** 2 + (gy - 20) ** 2) / 40.0) - 20.0
    terrain = Terrain(island + np.random.default_rng(3).normal(0.0, 0.5, (40, 60)), 1.0)
    world = _world(terrain, [10.0, 20.0])
    seabed = Seabed(terrain, world.bodies)
    rng = np.random.default_rng(4)
    pos = np.array([[20.0, 20.0, 0.0], [40.0, 10.0, 0.0]])
    best, looked = np.full(2, np.inf), 0
    for _ in range(400):
        pos[:, :2] += rng.normal(0.0, 0.3, (2, 2))
        shore, near = seabed.check(pos)
        every, shallow = seabed.lookup(pos)
        best = np.minimum(best, every)
        looked += shore is not None
        if shore is None:
            assert not near.any() and (shallow > seabed.reach).all()
        else:
            np.testing.assert_array_equal(near, shallow <= seabed.reach)
        np.testing.assert_array_equal(seabed.best, best)
    assert 0 < looked < 400


def _at(world: World, x: float, pitch: float = 0.0) -> BodyStates:
    pos = np.array([[x, 5.0, 0.0]])
    quat = np.array([[0.0, math.sin(pitch / 2), 0.0, math.cos(pitch / 2)]])
    z = np.zeros((1, 3))
    return BodyStates(0, 10_000_000, world.body_ids, pos, quat, z, z, z, z)


def test_a_bow_probe_below_the_bank_is_aground() -> None:
    """The bilinear ground is -0.06 m (the catamaran's keel) at x = 39.5 + 9.94/15 m; the bow
    probes are 0.95 m ahead of the origin."""
    terrain = _shore()
    world = _world(terrain, [10.0])
    seabed = Seabed(terrain, world.bodies)
    contact = 39.5 + 9.94 / 15 - 0.95
    for x, aground in ((10.0, False), (contact - 0.01, False), (contact + 0.01, True)):
        s = _at(world, x)
        _, near = seabed.check(s.position)
        assert bool(seabed.aground(s.position, s.orientation, near)[0]) is aground, x


def test_pitching_puts_the_bow_on_a_shoal() -> None:
    """A flat shoal 0.2 m deep: the level keel (-0.06 m) clears it, the bow pitched down by
    0.2 rad (at -0.95 sin 0.2 - 0.06 cos 0.2 = -0.25 m) does not."""
    shoal = Terrain(np.full((30, 50), -0.2), 1.0)
    world = _world(shoal, [10.0])
    seabed = Seabed(shoal, world.bodies)
    for pitch, aground in ((0.0, False), (0.2, True), (-0.2, True), (0.1, False)):
        s = _at(world, 10.0, pitch)
        _, near = seabed.check(s.position)
        assert bool(seabed.aground(s.position, s.orientation, near)[0]) is aground, pitch


def test_metrics_report_grounding_episodes_and_shore(tmp_path: Path) -> None:
    terrain = _shore()
    world = _world(terrain, [30.0])
    metrics = Metrics(world, Orders())
    track = [30.0, 35.0, 39.3, 39.5, 39.0, 30.0, 30.0] + [30.0] * 100 + [39.4]
    for tick, x in enumerate(track):
        s = _at(world, x)
        metrics.add(dataclasses.replace(s, tick=tick, stamp_ns=(tick + 1) * 10_000_000))
    metrics.write(tmp_path / "m.json")
    record = json.loads((tmp_path / "m.json").read_text())
    assert record["groundings"] == [
        {"vessel": "v0", "start_s": 0.03, "end_s": 0.04},  # the bow touches from x = 39.21 m
        {"vessel": "v0", "start_s": 1.08, "end_s": None},  # back again at the end
    ]
    assert record["vessels"]["v0"]["groundings"] == 2
    assert record["vessels"]["v0"]["nearest_shore"] == {"distance_m": pytest.approx(1.0),
                                                        "t_s": 0.04}  # fmt: skip


def test_vessels_of_different_models_each_by_their_own_probes() -> None:
    """A shoal 0.07 m deep: the WAM-V's keel (-0.089 m) touches, the catamaran's (-0.06 m, its
    probes padded to the WAM-V's count) does not."""
    shoal = Terrain(np.full((30, 50), -0.07), 1.0)
    cat = {"id": "cat", "pose": {"x_m": 10.0, "y_m": 10.0}}
    wamv = {"id": "wamv", "model": "wamv", "pose": {"x_m": 30.0, "y_m": 10.0}}
    data = {"name": "s", "vessels": [cat, wamv]}
    world = dataclasses.replace(World.resolve(parse_scenario(data)), terrain=shoal)
    seabed = Seabed(shoal, world.bodies)
    pos = np.array([[10.0, 10.0, 0.0], [30.0, 10.0, 0.0]])
    quat = np.tile([0.0, 0.0, 0.0, 1.0], (2, 1))
    _, near = seabed.check(pos)
    assert seabed.aground(pos, quat, near).tolist() == [False, True]
