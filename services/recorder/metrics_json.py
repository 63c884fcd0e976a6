"""`metrics.json`'s layout (DESIGN.md §7): what `metrics.Metrics` accumulated, as JSON.

Times are simulated seconds (a tick's stamp / 1e9), distances metres, the thrust impulse
N s. Keys are sorted and floats written by `repr`, so one seed gives the same bytes.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from catabot.bus.clock import NS_PER_S

if TYPE_CHECKING:
    from services.recorder.episodes import Episode
    from services.recorder.metrics import Metrics


def write_metrics(m: Metrics, path: Path, *, end_reason: str = "") -> None:
    """`end_reason`: how the run ended (`completed`, `interrupted`, a fault, `ended by ...`),
    so the file alone says whether its figures cover the whole run; `dropped`, only when a
    participant was (clock.policy drop): from when the run went on without it."""
    data = record(m) | {"end_reason": end_reason, "scenario": m.scenario, "seed": m.seed}
    data |= {"dropped": m.dropped} if m.dropped else {}
    text = json.dumps(_finite(data), indent=2, sort_keys=True, allow_nan=False)
    path.write_text(text + "\n")


def _finite(value: Any) -> Any:
    """null for a figure never measured (a run ended before its first tick had written
    `Infinity`, which JSON has not: Node and strict parsers refused the file)."""
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if isinstance(value, dict):
        return {k: _finite(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_finite(v) for v in value]
    return value


def record(m: Metrics) -> dict[str, Any]:
    vessels = {
        vid: {
            "distance_m": float(m.distance[k]),
            "max_speed_mps": float(np.sqrt(m.max_speed2[k])),
            "final_position_m": [float(v) for v in m.last[k]] if m.last is not None else None,
        }
        for k, vid in enumerate(m.ids)
    }
    for k in range(m.subjects):
        vessels[m.ids[k]] |= _subject(m, k)
    ids = m.body_ids
    return {
        "sim_time_s": m.stamp_ns / NS_PER_S,
        "states_skipped": m.skipped,
        "vessels": vessels,
        "closest_approach": _closest(m),
        "encounter_radius_m": m.radius,
        "encounters": [
            {
                "vessels": [ids[e.slot[0]], ids[e.slot[1]]],
                "cpa_m": e.least,
                "cpa_s": e.least_ns / NS_PER_S,
                **_span(e),
            }
            for e in m.encounters.all()
        ],
        "collisions": [
            {"bodies": [ids[e.slot[0]], ids[e.slot[1]]], **_span(e)} for e in m.collisions.all()
        ],
        "groundings": [{"vessel": ids[e.slot[0]], **_span(e)} for e in m.groundings.all()],
        "capsizes": [{"vessel": ids[e.slot[0]], **_span(e)} for e in m.capsizes.all()],
        "traffic_collisions": [
            {"bodies": [ids[e.slot[0]], ids[e.slot[1]]], **_span(e)} for e in m.fleet.all()
        ],
    }


def _subject(m: Metrics, k: int) -> dict[str, Any]:
    """What only a scenario vessel has: nearest bodies, its task, thrust, contact counts."""
    n, (impulse, unknown) = len(m.ids), m.thrust.totals()
    out: dict[str, Any] = {
        "nearest_vessel": _nearest(m, "vessel", k, m.body_ids),
        "nearest_buoy": _nearest(m, "buoy", k, m.body_ids[n:]),
        "nearest_shore": _nearest(m, "shore", k, None),
        "min_distance_m": {
            body: float(d)
            for body, d in zip(m.body_ids, m.least_gap[k], strict=True)
            if body != m.ids[k]
        },
        "thrust_impulse_Ns": float(impulse[k]),
        "thrust_unknown_s": float(unknown[k]),
        "collisions": sum(k in e.slot for e in m.collisions.all()),
        "groundings": sum(e.slot[0] == k for e in m.groundings.all()),
        "capsizes": sum(e.slot[0] == k for e in m.capsizes.all()),
        "max_tilt_rad": float(m.max_tilt[k]),
    }
    goals, last = m.goals, m.last
    if k in goals.rows:  # its keys in every run, also one that ended before its first tick
        g = int(list(goals.rows).index(k))
        reached = int(goals.reached_ns[g])
        out["goal"] = {
            "reached": reached >= 0,
            "time_to_goal_s": reached / NS_PER_S if reached >= 0 else None,
            "path_length_m": float(goals.path_m[g]) if reached >= 0 else None,
            "final_distance_m": None if last is None else float(goals.final_distance(last)[g]),
        }
    if k in m.routes.rows:
        r = int(list(m.routes.rows).index(k))
        rms = m.routes.rms()
        out["route"] = {"max_cross_track_m": float(m.routes.max()[r]),
                        "rms_cross_track_m": float(rms[r])}  # fmt: skip
    return out


def _nearest(m: Metrics, kind: str, k: int, names: list[str] | None) -> dict[str, Any] | None:
    near = m.nearest[kind]
    if not near.distance[k] < float("inf"):
        return None
    out: dict[str, Any] = {"distance_m": float(near.distance[k]), "t_s": near.at_ns[k] / NS_PER_S}
    if names is not None:
        out["id"] = names[int(near.what[k])]
    return out


def _closest(m: Metrics) -> dict[str, Any] | None:
    """The closest two vessels came, one of them a scenario vessel (centre to centre)."""
    near = m.nearest["vessel"]
    if not m.subjects or not (near.distance < float("inf")).any():
        return None
    k = int(near.distance.argmin())
    a, b = sorted((m.ids[k], m.body_ids[int(near.what[k])]))
    return {"distance_m": float(near.distance[k]), "vessels": [a, b],
            "stamp_ns": int(near.at_ns[k])}  # fmt: skip


def _span(e: Episode) -> dict[str, Any]:
    end = None if e.end_ns is None else e.end_ns / NS_PER_S
    return {"start_s": e.start_ns / NS_PER_S, "end_s": end}
