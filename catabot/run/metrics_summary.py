"""The navigation metrics in `catabot run`'s summary: one line per scenario vessel.

Read from the run folder's `metrics.json` (the recorder writes it as the run ends); a run
without one (no recorder, or a recorder that failed) prints nothing here.
"""

from __future__ import annotations

import contextlib
import json
from collections.abc import Sequence
from pathlib import Path
from typing import Any

MAX_LINES = 8


def metrics_lines(run_dir: Path, order: Sequence[str] = ()) -> list[str]:
    """`  <vessel>: goal ..., nearest ..., collisions ..., thrust impulse ...` per scenario
    vessel (the vessels measured against everything else: they have `nearest_vessel`)."""
    record: Any = None
    with contextlib.suppress(OSError, ValueError):
        record = json.loads((run_dir / "metrics.json").read_text())
    if not isinstance(record, dict) or not isinstance(record.get("vessels"), dict):
        return []
    own = own_vessels(record)
    rank = {vid: k for k, vid in enumerate(order)}  # the scenario's: metrics.json sorts its keys
    ids = sorted(own, key=lambda vid: (rank.get(vid, len(rank)), vid))
    lines = [f"  {vid}: " + "; ".join(filter(None, vessel_parts(own[vid]))) for vid in ids]
    if len(lines) > MAX_LINES:  # a fleet of scenario vessels: the file has them all
        more = len(lines) - MAX_LINES + 1
        lines[MAX_LINES - 1 :] = [f"  ... {more} more in {run_dir / 'metrics.json'}"]
    return lines + _traffic(record)


def own_vessels(record: dict[str, Any] | None) -> dict[str, dict[str, Any]]:
    """The scenario vessels' figures in a metrics.json record (those measured against
    everything else: `nearest_vessel`), not the traffic boats'; the summary and `catabot
    results` alike."""
    vessels = (record or {}).get("vessels")
    if not isinstance(vessels, dict):
        return {}
    return {v: m for v, m in vessels.items() if isinstance(m, dict) and "nearest_vessel" in m}


def _traffic(record: dict[str, Any]) -> list[str]:
    """The traffic's own collisions, in a run that has traffic (boats without the scenario
    vessels' figures) or where any happened."""
    hits = record.get("traffic_collisions")
    vessels = record["vessels"].values()
    boats = any(isinstance(m, dict) and "nearest_vessel" not in m for m in vessels)
    if not isinstance(hits, list) or not (boats or hits):
        return []
    noun = "collision" if len(hits) == 1 else "collisions"
    return [f"  traffic: {len(hits)} {noun} among its boats and buoys"]


def vessel_parts(m: dict[str, Any]) -> list[str]:
    """A scenario vessel's figures, as the console's summary line and the report give them."""
    goal, route = m.get("goal"), m.get("route")
    near = [
        f"{kind} {n['distance_m']:.2f} m" + (f" ({n['id']})" if "id" in n else "")
        for kind in ("vessel", "buoy", "shore")
        if (n := m.get(f"nearest_{kind}"))
    ]
    xte = ""
    if isinstance(route, dict):
        top, rms = route["max_cross_track_m"], route["rms_cross_track_m"]
        xte = f"cross-track max {top:.2f} m, RMS {rms:.2f} m"
    impulse = f"thrust impulse {m['thrust_impulse_Ns']:.0f} N s"
    if m.get("thrust_unknown_s"):
        impulse += f" (+{m['thrust_unknown_s']:.1f} s under velocity control)"
    return [
        _goal(goal) if goal else "",
        xte,
        "nearest " + ", ".join(near) if near else "",
        f"collisions {m['collisions']}, groundings {m['groundings']}"
        + (f", capsizes {m['capsizes']}" if m.get("capsizes") else ""),
        impulse,
    ]  # fmt: skip


def _goal(goal: dict[str, Any]) -> str:
    if goal.get("reached"):
        return f"goal reached at {goal['time_to_goal_s']:.2f} s ({goal['path_length_m']:.1f} m)"
    left = goal.get("final_distance_m")
    return "goal not reached" + (f" ({left:.1f} m short)" if left is not None else "")
