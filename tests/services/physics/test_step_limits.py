"""The step limit is real (catabot/world/step_limits.py): the WAM-V, whose roll is the
bundled models' fastest (0.365 s), rolls back upright from a heel at the longest step the
check allows, and diverges at the schema's longest step, 0.1 s, though that is under the
linear limit (0.108 s; the quadratic damping is left out of it, hence the margin): an
audit's WAM-V at dt 0.1 s rolled itself apart in 1.8 s."""

from __future__ import annotations

import numpy as np
import pytest

from catabot.config.load import parse_scenario
from catabot.world import rotations, step_limits
from catabot.world.world import World
from services.physics.diverged import PhysicsDiverged
from services.physics.setup import build_world

HEEL = 0.05  # rad


def _roll_after(dt_s: float, seconds: float) -> float:
    data = {"dt_ns": round(dt_s * 1e9), "duration_s": 10.0,
            "vessels": [{"id": "v", "model": "wamv", "pose": {"roll_rad": HEEL}}]}  # fmt: skip
    physics = build_world(World.resolve(parse_scenario(data)))
    for _ in range(round(seconds / dt_s)):
        physics.step()
    rot = rotations.matrices(physics.state_arrays().orientation)[0]
    return float(np.arctan2(rot[2, 1], rot[2, 2]))


def test_at_the_longest_step_allowed_it_rolls_back_upright() -> None:
    assert abs(_roll_after(0.08, 10.0)) < 0.1 * HEEL  # the limit: 0.0864 s


def test_at_the_schemas_longest_step_it_diverges(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(step_limits, "MARGIN", 1.0)  # let the world resolve at 0.1 s
    with pytest.raises(PhysicsDiverged):
        _roll_after(0.1, 10.0)
