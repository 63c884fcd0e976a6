"""Notes on a traffic plan that runs but not as written, said by `scenario validate` and
before a run.

Why: a trial's `circle.speed_mps: 8` was taken, and the monohulls held 5.96 m/s, their top
speed under full thrust, without a word (the ego's script asking too much is said by
physics; the traffic's set-points are clamped to what the boats reach). A note, not a
refusal: the boats still do their best.
"""

from __future__ import annotations

from collections import Counter

from catabot.world.course import top_speed_mps
from catabot.world.world import World

MOVING = ("circle", "waypoints")


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
