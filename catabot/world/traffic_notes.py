"""Notes on a traffic plan that runs but not as written, said by `scenario validate` and
before a run.

Why: a trial's `circle.speed_mps: 8` was taken, and the monohulls held 5.96 m/s, their top
speed under full thrust, without a word (the ego's script asking too much is said by
physics; the traffic's set-points are clamped to what the boats reach). A note, not a
refusal: the boats still do their best.
"""

from __future__ import annotations

from collections import Counter

from catabot.config.traffic import MAX_YAW_RATE
from catabot.world.course import top_speed_mps
from catabot.world.world import World

MOVING = ("circle", "waypoints")


def traffic_notes(world: World) -> list[str]:
    """Every note on the plan: its circles, then its speeds."""
    return [*circle_notes(world), *speed_notes(world)]


def circle_notes(world: World) -> list[str]:
    """Circles tighter than the traffic can turn at their speed: taken (the boats circle
    wider), but said; a trial's 2-4 m circles came out at 16 m, unsaid. From the plan, so
    per-boat behaviours and radii count as drawn."""
    tight = [b for b in world.traffic.boats
             if b.behaviour == "circle" and b.radius_m < b.speed_mps / MAX_YAW_RATE]  # fmt: skip
    if not tight:
        return []
    speed = max(b.speed_mps for b in tight)
    return [f"note: traffic.circle.radius_m: {len(tight)} circling boat(s) with radii from "
            f"{min(b.radius_m for b in tight):.3g} m; at speed_mps {speed:g} a traffic boat "
            f"turns at most {MAX_YAW_RATE:g} rad/s, a circle of {speed / MAX_YAW_RATE:.3g} m "
            "at least, so smaller circles come out that wide"]  # fmt: skip


def speed_notes(world: World) -> list[str]:
    """Boats set faster than their model's top speed, one note per behaviour and model."""
    groups: Counter[tuple[str, str, float]] = Counter()
    first: dict[tuple[str, str, float], str] = {}
    for boat in world.traffic.boats:
        if boat.behaviour in MOVING:
            key = (boat.behaviour, boat.model, boat.speed_mps)
            groups[key] += 1
            first.setdefault(key, boat.id)
    notes = []
    for key, count in sorted(groups.items()):
        behaviour, model, speed = key
        top = top_speed_mps(world.body(first[key]).model)
        if speed > top:
            notes.append(f"note: traffic.{behaviour}.speed_mps {speed:g}: {count} {behaviour} "
                         f"boat(s) of model {model!r} reach {top:.3g} m/s at most (full "
                         "thrust against their damping), so they go that fast")  # fmt: skip
    return notes
