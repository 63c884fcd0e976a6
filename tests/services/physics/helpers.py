"""Worlds for physics unit tests, resolved as a run resolves them."""

from __future__ import annotations

from typing import Any

from catabot.config.load import parse_scenario
from catabot.world.world import Body, World


def vessels(*configs: dict[str, Any]) -> tuple[Body, ...]:
    """The vessels of a scenario made of `configs` (bundled catamaran unless they say)."""
    return World.resolve(parse_scenario({"vessels": list(configs)})).vessels
