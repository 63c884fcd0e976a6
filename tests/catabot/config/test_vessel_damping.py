"""A hull's lift resists its sideslip (catabot/config/vessel.py, Damping.lift_uv): a positive
Y_uv, which an audit found accepted, pushes the hull along its sideslip, negative sway
damping above |u| = Y_v / Y_uv; a non-finite one is refused with the field named."""

from __future__ import annotations

import re

import pytest

from catabot.config.vessel import VesselModelError, load_vessel_model, parse_vessel_model


@pytest.mark.parametrize(
    ("lift", "said"),
    [((60.0, 8.0), "must be <= 0 (got 60.0)"), ((float("nan"), 8.0), "must be a finite number")],
)
def test_a_lift_along_the_sideslip_is_refused(lift: tuple[float, float], said: str) -> None:
    data = load_vessel_model("monohull").model_dump(mode="json")
    data["damping"]["lift_uv"] = list(lift)
    with pytest.raises(VesselModelError, match=re.escape(f"damping.lift_uv.0: {said}")):
        parse_vessel_model(data, source="m.json")
