"""Fixtures shared by the library tests."""

from collections.abc import Iterator

import pytest

from tests.catabot.bus.lockstep_world import World


@pytest.fixture
def world() -> Iterator[World]:
    w = World()
    try:
        yield w
    finally:
        w.close()
