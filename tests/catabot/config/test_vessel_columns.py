"""Buoyancy columns that all lie on one line are refused (catabot/config/vessel.py): they give
no righting moment about it. An audit's monohull with `columns_across: 1` fell from a 3
degree heel onto its side, a catamaran with `columns_along: 1` pitched to -75 degrees under
thrust; a catamaran's two hulls with one column across each still right it in roll."""

from __future__ import annotations

from typing import Any

import pytest

from catabot.config.vessel import VesselModelError, load_vessel_model, parse_vessel_model


def _with_columns(name: str, **columns: int) -> dict[str, Any]:
    data = load_vessel_model(name).model_dump(mode="json")
    data["hulls"] = [{**hull, **columns} for hull in data["hulls"]]
    return data


def test_a_monohull_with_one_column_across_is_refused_for_roll() -> None:
    with pytest.raises(VesselModelError) as err:
        parse_vessel_model(_with_columns("monohull", columns_across=1), source="m.json")
    assert str(err.value) == (
        "vessel model 'm.json': hulls.0.columns_across: every buoyancy column lies at y = 0, "
        "one line: no righting moment in roll; give a hull 2 or more"
    )


def test_a_catamaran_with_one_column_along_is_refused_for_pitch() -> None:
    with pytest.raises(VesselModelError, match=r"columns_along: .* in pitch"):
        parse_vessel_model(_with_columns("catabot", columns_along=1))


def test_two_hulls_side_by_side_with_one_column_across_each_are_a_model() -> None:
    model = parse_vessel_model(_with_columns("catabot", columns_across=1))
    assert [h.across for h in model.hulls] == [1, 1]
