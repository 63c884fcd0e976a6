"""What the trajectory views and the metrics figure mark besides the tracks: each traffic
boat's number, and where and when bodies touched or ran aground (metrics.json's episodes).

Why: a run whose summary said "traffic: 1 collision" or "ego: collisions 1" drew nothing
of it: among 100 white tracks the reader could not find where, nor on the closest-approach
curve when. An episode is drawn where it began: a contact between the two bodies' positions
at its start, a grounding at the vessel's.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from matplotlib.axes import Axes

from catabot.world.world import World
from services.plots.series import RunSeries

NAMED_BOATS = 40  # traffic boats numbered on the trajectories, at most
KINDS = {  # metrics.json list: (legend text, marker, colour)
    "collisions": ("collision", "X", "#ff2020"),
    "traffic_collisions": ("traffic contact", "X", "#ffd0d0"),
    "groundings": ("grounding", "^", "#8c4a1e"),
}


@dataclass(frozen=True)
class Episode:
    kind: str  # a KINDS key
    start_s: float
    end_s: float | None  # None: still touching when the run ended
    bodies: tuple[str, ...]


def boat_names(ax: Axes, world: World, xy: np.ndarray) -> None:
    """Each traffic boat's number where its track ends (up to `NAMED_BOATS`): which white
    track is boat_007's, to read beside its CSV or a takeover."""
    first = len(world.scenario.vessels)
    if len(world.vessels) - first > NAMED_BOATS:
        return
    for row in range(first, len(world.vessels)):
        number = world.vessels[row].id.rsplit("_", 1)[-1].lstrip("0") or "0"
        ax.annotate(number, xy[-1, row], fontsize=6, color="white", xytext=(3, 3),
                    textcoords="offset points")  # fmt: skip


def episodes(metrics: dict[str, Any] | None) -> list[Episode]:
    """Every contact and grounding metrics.json lists, in its order; malformed entries are
    skipped (the plots draw what they can read)."""
    out = []
    for kind in KINDS:
        for entry in (metrics or {}).get(kind, []):
            bodies = entry.get("bodies") or [entry.get("vessel")]
            try:
                start, end = float(entry["start_s"]), entry.get("end_s")
                end = None if end is None else float(end)
            except (KeyError, TypeError, ValueError):
                continue
            out.append(Episode(kind, start, end, tuple(str(b) for b in bodies)))
    return out


def where(data: RunSeries, episode: Episode) -> np.ndarray | None:
    """The plan position (2,) an episode began at; None for a body the run does not have."""
    known = set(data.run.world.body_ids)
    if not episode.bodies or not set(episode.bodies) <= known:
        return None
    k = min(int(np.searchsorted(data.t, episode.start_s)), len(data.t) - 1)
    rows = [data.run.world.body(b).row for b in episode.bodies]
    return np.asarray(data.states.position[k, rows, :2].mean(axis=0))


def mark_places(ax: Axes, data: RunSeries) -> None:
    """A marker per episode where it began, one legend entry per kind with its count."""
    listed = episodes(data.metrics)
    for kind, (text, marker, color) in KINDS.items():
        found = [where(data, e) for e in listed if e.kind == kind]
        points = np.array([p for p in found if p is not None]).reshape(-1, 2)
        if len(points):
            ax.scatter(points[:, 0], points[:, 1], s=90, marker=marker, c=color, zorder=5,
                       edgecolors="black", lw=0.7, label=f"{text}s ({len(points)})")  # fmt: skip


def mark_times(ax: Axes, data: RunSeries) -> None:
    """The scenario vessels' contacts (with a vessel or a buoy) as shaded spans over time."""
    spans = [e for e in episodes(data.metrics) if e.kind == "collisions"]
    for k, e in enumerate(spans):
        label = f"collision ({len(spans)})" if k == 0 else None
        end = float(data.t[-1]) if e.end_s is None else e.end_s
        ax.axvspan(e.start_s, max(end, e.start_s + 0.1), color=KINDS["collisions"][2],
                   alpha=0.3, label=label)  # fmt: skip
    if spans:
        ax.legend(fontsize=8)
