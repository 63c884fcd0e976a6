"""The one rotation and cross-product rules (catabot/world/rotations.py) physics and sensors
share: the bits of the textbook forms."""

from __future__ import annotations

import numpy as np

from catabot.world import rotations


def test_cross_gives_the_bits_of_np_cross_for_one_vector_and_for_batches() -> None:
    rng = np.random.default_rng(11)
    for _ in range(50):
        a, b = rng.normal(size=3) * 10, rng.normal(size=3) * 1e-3
        assert np.array_equal(rotations.cross(a, b), np.cross(a, b))
    a, b = rng.normal(size=(7, 5, 3)), rng.normal(size=(5, 3))  # broadcast as np.cross does
    assert np.array_equal(rotations.cross(a, b), np.cross(a, b))


def test_matrices_are_the_rotations_of_their_quaternions() -> None:
    rng = np.random.default_rng(3)
    q = rng.normal(size=(20, 4))
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    got = rotations.matrices(q)
    for quat, r in zip(q, got, strict=True):
        np.testing.assert_allclose(r, rotations.matrix(quat), atol=1e-15)
        np.testing.assert_allclose(r @ r.T, np.eye(3), atol=1e-12)


def test_vertical_is_the_map_up_row_of_the_rotation() -> None:
    rng = np.random.default_rng(5)
    q = rng.normal(size=(20, 4))
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    v = rng.normal(size=(20, 3))
    expected = np.einsum("nj,nj->n", rotations.matrices(q)[:, 2, :], v)
    assert np.allclose(rotations.vertical(q, v), expected, atol=1e-12)


def test_a_product_turns_as_its_matrices_do() -> None:
    rng = np.random.default_rng(6)
    a, b = (q / np.linalg.norm(q, axis=1, keepdims=True) for q in rng.normal(size=(2, 30, 4)))
    turned = rotations.product(a, b)
    assert np.allclose(rotations.matrices(turned), rotations.matrices(a) @ rotations.matrices(b))
    assert (turned[:, 3] >= 0).all()
