"""A row per run and scenario vessel: the swept fields, how the run ended, the vessel's metrics.

Read from each run folder's `scenario.json` (the fields, `--set` included), `log/run.json`
(how it ended, its times) and `metrics.json` (the recorder's figures). A run whose recorder
wrote no metrics (it failed before its first tick) still has its row, blank where nothing
was measured, so a sweep's table shows every run it started.
"""

from __future__ import annotations

import json
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from catabot.config.differences import flat_fields, swept_fields, timeline
from catabot.config.load import load_scenario
from catabot.config.scenario import Scenario
from catabot.run.ending import end_reason
from catabot.run.metrics_summary import own_vessels

# The measured columns: name -> (where in a vessel's metrics, or the run's), in table order.
RUN_COLUMNS = ("seed", "reason", "error", "sim_s", "wall_s")
VESSEL_COLUMNS = (
    "goal_reached", "time_to_goal_s", "path_length_m", "final_distance_m",
    "max_cross_track_m", "rms_cross_track_m", "nearest_vessel_m", "nearest_vessel",
    "nearest_buoy_m", "nearest_shore_m", "collisions", "groundings", "capsizes",
    "thrust_impulse_Ns", "thrust_unknown_s", "distance_m", "max_speed_mps",
)  # fmt: skip
AFTER = ("closest_approach_m", "traffic_collisions", "git_commit")


@dataclass(frozen=True)
class RunRecord:
    """One run folder as read: its scenario and its two result files (None where absent)."""

    folder: Path
    scenario: Scenario
    run: dict[str, Any] | None
    metrics: dict[str, Any] | None


def read(folder: Path) -> RunRecord:
    """A run folder's record; an unreadable scenario raises its ConfigError."""
    return RunRecord(
        folder, load_scenario(folder / "scenario.json"),
        _json(folder / "log" / "run.json"), _json(folder / "metrics.json"),
    )  # fmt: skip


def _json(path: Path) -> dict[str, Any] | None:
    try:
        value = json.loads(path.read_text())
    except (OSError, ValueError):
        return None
    return value if isinstance(value, dict) else None


def table(records: list[RunRecord]) -> tuple[list[str], list[dict[str, Any]]]:
    """The header (run, vessel, the swept fields, then the measured columns) and the rows."""
    swept = [k for k in swept_fields([r.scenario for r in records]) if k not in RUN_COLUMNS]
    values = [flat_fields(r.scenario) for r in records]
    columns = [column for key in swept for column in _split(key, values)]
    timelines = ["; ".join(timeline(r.scenario)) or None for r in records]
    if len(set(timelines)) > 1:  # a sweep over the timeline looked like repeats of one run
        columns.append("settings")
        for v, text in zip(values, timelines, strict=True):
            v["settings"] = text
    names = _names([r.folder for r in records])
    header = ["run", "vessel", *columns, *RUN_COLUMNS, *VESSEL_COLUMNS, *AFTER]
    rows = zip(records, values, names, strict=True)
    return header, [row for r, v, n in rows for row in _rows(r, v, columns, n)]


def _names(folders: list[Path]) -> list[str]:
    """Each run folder below the folders' common parent: `tl/a` and `live/a`, not `a`
    twice (a sweep in one folder: its runs' names)."""
    parents = [str(f.resolve().parent) for f in folders]
    common = Path(os.path.commonpath(parents)) if parents else Path()
    return [os.path.relpath(f.resolve(), common) for f in folders]


def _split(key: str, values: list[dict[str, Any]]) -> list[str]:
    """A swept list of one length in every run (a current's [east, north], a program's
    args) as a column per item that differs, `key.i` as `--set` names it: numbers pandas
    reads as numbers (a plot against `water.current.velocity_mps.1`), not JSON text. The
    columns the key became."""
    found = [v.get(key) for v in values]
    lists = [x for x in found if isinstance(x, list)]
    if len(lists) != len(found) or len({len(x) for x in lists}) != 1:
        return [key]
    items = [i for i in range(len(lists[0])) if len({json.dumps(x[i]) for x in lists}) > 1]
    for v, x in zip(values, lists, strict=True):
        v |= {f"{key}.{i}": x[i] for i in items}
    return [f"{key}.{i}" for i in items]


def _rows(
    record: RunRecord, values: dict[str, Any], columns: list[str], name: str
) -> list[dict[str, Any]]:
    common = {"run": name, **{k: values.get(k) for k in columns}}
    common |= _run_cells(record) | _after(record.metrics)
    vessels = own_vessels(record.metrics)
    if not vessels:  # nothing measured: the run's row alone
        return [common | {"vessel": None}]
    return [common | {"vessel": vid} | vessel_columns(m) for vid, m in vessels.items()]


def _run_cells(record: RunRecord) -> dict[str, Any]:
    run = record.run or {}
    return {
        "seed": record.scenario.seed,
        "reason": end_reason(record.run, record.metrics),
        "error": run.get("error") or None,
        "sim_s": run.get("sim_s", (record.metrics or {}).get("sim_time_s")),
        "wall_s": run.get("wall_s"),
        "git_commit": run.get("git_commit"),  # a sweep may span a commit (results says so)
    }


def _after(metrics: dict[str, Any] | None) -> dict[str, Any]:
    m = metrics or {}
    close, hits = m.get("closest_approach"), m.get("traffic_collisions")
    return {
        "closest_approach_m": close.get("distance_m") if isinstance(close, dict) else None,
        "traffic_collisions": len(hits) if isinstance(hits, list) else None,
    }


def vessel_columns(m: dict[str, Any]) -> dict[str, Any]:
    """A scenario vessel's figures in metrics.json as flat cells (blank where it has none:
    no goal, no route, no buoy in the scenario)."""
    goal, route = m.get("goal") or {}, m.get("route") or {}
    nearest = {k: m.get(f"nearest_{k}") or {} for k in ("vessel", "buoy", "shore")}
    return {
        "goal_reached": goal.get("reached"),
        "time_to_goal_s": goal.get("time_to_goal_s"),
        "path_length_m": goal.get("path_length_m"),
        "final_distance_m": goal.get("final_distance_m"),
        "max_cross_track_m": route.get("max_cross_track_m"),
        "rms_cross_track_m": route.get("rms_cross_track_m"),
        "nearest_vessel_m": nearest["vessel"].get("distance_m"),
        "nearest_vessel": nearest["vessel"].get("id"),
        "nearest_buoy_m": nearest["buoy"].get("distance_m"),
        "nearest_shore_m": nearest["shore"].get("distance_m"),
        **{k: m.get(k) for k in ("collisions", "groundings", "capsizes", "thrust_impulse_Ns")},
        "thrust_unknown_s": m.get("thrust_unknown_s"),  # under velocity control: not in the impulse
        **{k: m.get(k) for k in ("distance_m", "max_speed_mps")},
    }
