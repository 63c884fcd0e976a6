"""The traffic section's refusals made before any boat is drawn, each naming its field.

Planning draws thousands of starts and paths; a request it can never meet (buoys that
cannot all fit, a given waypoint on land) would end minutes later in "no free open water",
naming neither the field nor the cause.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from catabot.config.base import ScenarioError
from catabot.config.terrain import TerrainError
from catabot.config.traffic import TrafficConfig
from catabot.world.clearance import densify
from catabot.world.placement import CLEARANCE_M
from catabot.world.terrain import Terrain

MAX_BUOY_COVER = 0.05
TRACK_DEPTH_M = 2.0  # water under every point of a boat's track: boats must not run aground
Wet = Callable[[np.ndarray, np.ndarray], bool]  # every point of a track in deep water


def check_room(cfg: TrafficConfig, buoy_r: float) -> None:
    """Refuse at once a traffic whose waypoint buoys cannot all be laid clear of each
    other: each buoy keeps others out of a disc of radius 2 r + clearance, and once
    those discs cover 5% of the region a path of many points almost never lands clear
    (planning would run for minutes, then fail)."""
    w, mix = cfg.waypoints, cfg.behaviour_mix
    if w.points is not None or not w.buoys:
        return
    share = mix.get("waypoints", 0.0) / sum(mix.values())
    buoys = cfg.count * share * w.count
    width, height = w.region.size_m
    covered = buoys * math.pi * (2 * buoy_r + CLEARANCE_M) ** 2 / (width * height)
    if covered > MAX_BUOY_COVER:
        raise ScenarioError(
            f"traffic: about {buoys:.0f} waypoint buoys ({cfg.count} boats x "
            f"{share:.0%} on waypoints x {w.count} points) in a {width:g} x {height:g} m "
            f"region would keep {covered:.0%} of it; at most {MAX_BUOY_COVER:.0%}: use "
            "fewer points or boats, a larger traffic.waypoints.region, or buoys: false"
        )


def check_given(cfg: TrafficConfig, terrain: Terrain | None, wet: Wet) -> None:
    """Given waypoints, and the legs between them, in water `TRACK_DEPTH_M` deep, each
    refusal naming its field: a point on land used to end 2000 start draws later in
    "no free open water for boat 1", which named neither."""
    if terrain is None:
        return
    loop = cfg.waypoints.mode == "loop"
    given = [("traffic.waypoints.points", cfg.waypoints.points)]
    given += [(f"traffic.boats.{j}.points", b.points) for j, b in enumerate(cfg.boats)]
    for field, points in given:
        for k, (x, y) in enumerate(points or ()):
            try:
                terrain.check_water(x, y, what="waypoint", depth_m=TRACK_DEPTH_M)
            except TerrainError as exc:
                raise ScenarioError(f"{field}.{k}: {exc}") from None
        if points and len(points) > 1:
            _check_legs(field, np.array(points, dtype=np.float64), wet, loop=loop)


def _check_legs(field: str, points: np.ndarray, wet: Wet, *, loop: bool) -> None:
    closed = np.vstack([points, points[:1]]) if loop else points
    for k in range(len(closed) - 1):
        if not wet(*densify(closed[k : k + 2], loop=False)):
            a, b = closed[k].tolist(), closed[k + 1].tolist()
            raise ScenarioError(
                f"{field}: the leg from ({a[0]:g}, {a[1]:g}) to ({b[0]:g}, {b[1]:g}) "
                f"crosses land or water under {TRACK_DEPTH_M:g} m deep"
            )
