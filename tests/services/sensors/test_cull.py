"""The (ray, body) pre-test: bundled cones must keep every pair the one-by-one test keeps."""

from __future__ import annotations

import numpy as np

from services.sensors.cull import CHUNK, MIN_RAYS, cone_pairs, grid_pairs


def _dense(d: np.ndarray, axis: np.ndarray, dist: np.ndarray, cos_half: np.ndarray) -> set:
    ray, body = np.nonzero(np.dot(d, axis.T) >= cos_half * dist)
    return set(zip(ray.tolist(), body.tolist(), strict=True))


def test_bundled_cones_keep_exactly_the_pairs_of_the_full_product() -> None:
    rng = np.random.default_rng(3)
    el, az = np.meshgrid(np.radians(np.linspace(-15, 15, 7)), np.linspace(0, 6.28, 301))
    d = np.stack([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)], -1)
    d = d.reshape(-1, 3)  # 2107 rays: the last bundle is partial
    axis = rng.normal(size=(40, 3)) * [30.0, 30.0, 2.0]
    dist = np.linalg.norm(axis, axis=1)
    cos_half = np.cos(rng.uniform(0.01, 0.3, 40))
    cos_half[:2] = -1.0  # every direction: an origin inside the body's cone
    ray, body = cone_pairs(d, axis, dist, cos_half)
    assert d.shape[0] >= MIN_RAYS and d.shape[0] % CHUNK and ray.size > 2 * d.shape[0]
    assert set(zip(ray.tolist(), body.tolist(), strict=True)) == _dense(d, axis, dist, cos_half)
    assert np.all(np.diff(ray * 40 + body) > 0)  # sorted by ray, then body


def test_a_bundle_of_opposite_rays_keeps_its_pairs() -> None:
    d = np.tile([[1.0, 0.0, 0.0], [-1.0, 0.0, 0.0]], (CHUNK * 64, 1))
    axis = np.array([[10.0, 0.0, 0.0], [-10.0, 0.0, 0.0]])
    ray, body = cone_pairs(d, axis, np.array([10.0, 10.0]), np.array([0.99, 0.99]))
    assert d.shape[0] >= MIN_RAYS and ray.size == d.shape[0]
    assert np.array_equal(body, (d[ray, 0] < 0).astype(np.intp))


def test_grid_pairs_hold_every_ray_inside_each_cone() -> None:
    rng = np.random.default_rng(4)
    elevations, columns = np.radians(np.linspace(-15.0, 15.0, 32)), 512
    el, az = np.meshgrid(elevations, 2 * np.pi * np.arange(columns) / columns, indexing="ij")
    d = np.stack([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)], -1)
    axis = rng.normal(size=(60, 3)) * [30.0, 30.0, 3.0]
    axis[:3] = [[0.0, 0.0, -1.0], [0.0, 0.0, 1.0], [5.0, 0.0, 0.0]]  # vertical, on a channel
    unit = axis / np.linalg.norm(axis, axis=1, keepdims=True)
    cos_half = np.cos(rng.uniform(0.001, 0.5, 60))
    cos_half[:2] = [np.cos(np.radians(80.0)), -1.0]
    ray, body = grid_pairs(unit, cos_half, elevations, columns)
    inside = _dense(d.reshape(-1, 3), unit, np.ones(60), cos_half)
    got = set(zip(ray.tolist(), body.tolist(), strict=True))
    assert inside <= got and len(got) < 1.5 * len(inside) + 200
    assert np.all(np.diff(ray * 60 + body) > 0)
