"""What every sensor model shares: its error class and checks of its inputs.

A sensor's noise comes from its own generator, `catabot.world.seeding.rng(seed,
"<vessel>/<sensor>")`, so a run's samples do not depend on which process hosts the sensor,
on how many other sensors exist, or on the order they were built in (DESIGN.md §2).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Protocol

import numpy as np
from numpy.typing import NDArray

from catabot.errors import CataBotError
from catabot.world import rotations

Array = NDArray[np.float64]


class SensorError(CataBotError, ValueError):
    """A sensor configuration or input that cannot give a meaningful sample."""


def finite_vector(values: Sequence[float], what: str, length: int = 3) -> Array:
    """`values` as a float array of `length`, refusing NaN/inf with a message naming `what`."""
    arr = np.asarray(values, dtype=np.float64)
    if arr.shape != (length,) or not np.isfinite(arr).all():
        raise SensorError(f"{what} must be {length} finite numbers (got {tuple(values)!r})")
    return arr


def non_negative(value: float, what: str) -> float:
    """A finite, non-negative float (a standard deviation, a rate...)."""
    if not (math.isfinite(value) and value >= 0.0):
        raise SensorError(f"{what} must be a finite number >= 0 (got {value!r})")
    return float(value)


def rotation_from_quaternion(q: Sequence[float]) -> Array:
    """Body-to-map rotation of a unit quaternion (x, y, z, w), normalised first (a state rounded
    in transit still gives a proper rotation); a zero or non-finite one is refused."""
    rot = rotations.matrix(finite_vector(q, "orientation quaternion (x, y, z, w)", 4))
    if rot is None:
        raise SensorError(f"orientation quaternion has zero length (got {tuple(q)!r})")
    return rot


def rotations_from_quaternions(q: Array) -> Array | None:
    """(n, 3, 3) rotations of n quaternions, the same bits as `rotation_from_quaternion` one
    by one, or None if any is non-finite or of zero length (the caller then names it)."""
    return rotations.normalised_matrices(q)


def rows_of(a: Array, rows: NDArray[np.intp]) -> Array:
    """a[rows] of an (N, 3) array; a shared origin (stride 0) stays a view: np.take would
    first copy the whole broadcast array."""
    if a.strides[0] == 0:
        return np.broadcast_to(a[0], (rows.size, a.shape[1]))
    return np.take(a, rows, axis=0)


class Nearest(Protocol):
    """The nearest hit so far of each ray (the scene's), updated in place by the bodies'
    and the water's casts."""

    @property
    def rng(self) -> NDArray[np.float64]: ...
    @property
    def normal(self) -> NDArray[np.float32]: ...
    @property
    def cls(self) -> NDArray[np.uint8]: ...
    @property
    def inst(self) -> NDArray[np.int32]: ...
