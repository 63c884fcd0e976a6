"""The scenario digest every process of a run checks against the conductor's (Tick.digest)."""

from __future__ import annotations

from typing import Any

from catabot.config.load import _names_only, digest, parse_scenario


def _scenario(**more: Any) -> dict[str, Any]:
    return {"name": "d", "duration_s": 2.0, "vessels": [{"id": "ego"}], **more}


def test_any_field_changes_the_digest_but_not_where_files_are_kept() -> None:
    base = digest(parse_scenario(_scenario()))
    assert base == digest(parse_scenario(_scenario())) and len(base) == 12
    moved = _scenario(vessels=[{"id": "ego", "pose": {"x_m": 5.0, "y_m": 0.0}}])
    assert digest(parse_scenario(moved)) != base
    assert digest(parse_scenario(_scenario(dt_ns=20_000_000))) != base
    assert digest(parse_scenario(_scenario(seed=9))) != base


def test_files_count_by_name_only() -> None:
    """Each host may keep the terrain or a model in a folder of its own."""
    data = {"terrain": {"elevation_image": "/home/a/data/bay.png"}, "ros": {"ns": "/"}}
    other = {"terrain": {"elevation_image": "/mnt/b/bay.png"}, "ros": {"ns": "/"}}
    assert (
        _names_only(data)
        == _names_only(other)
        == {"terrain": {"elevation_image": "bay.png"}, "ros": {"ns": "/"}}
    )
