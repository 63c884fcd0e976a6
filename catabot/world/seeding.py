"""Randomness, one rule (DESIGN.md §2): every random source has its own generator, seeded with
the scenario seed and the source's own name.

So a sensor's noise does not depend on which process hosts it, on how many other sources
exist or on the order they were built in; adding a sensor moves no traffic boat. The shape
is Gymnasium's `seeding.np_random`: `rng(seed, name)` gives a NumPy `Generator`. The name's
hash is CRC-32 (stable across processes and Python versions, unlike the salted `hash`).
"""

from __future__ import annotations

import zlib

import numpy as np

from catabot.errors import CataBotError

SEED_LIMIT = 2**63  # seeds are 0 <= seed < 2**63 (a signed 64-bit integer in any language)


class SeedError(CataBotError, ValueError):
    """A seed or a source name that cannot seed a generator."""


def rng(seed: int, name: str) -> np.random.Generator:
    """The generator of the random source `name` in a scenario seeded with `seed`."""
    return np.random.default_rng([check_seed(seed), name_hash(name)])


def check_seed(seed: int) -> int:
    if isinstance(seed, bool) or not isinstance(seed, int | np.integer):
        raise SeedError(f"seed must be an integer (got {seed!r})")
    if not 0 <= int(seed) < SEED_LIMIT:
        raise SeedError(f"seed must be in [0, 2**63) (got {seed})")
    return int(seed)


def name_hash(name: str) -> int:
    """The 32-bit hash of a source name, the same in every process."""
    if not isinstance(name, str) or not name:
        raise SeedError(f"a random source needs a non-empty name (got {name!r})")
    return zlib.crc32(name.encode("utf-8"))
