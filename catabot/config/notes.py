"""Notes on a valid scenario that is likely not what its author meant, said before the run.

A participant given several vessels (a catabot.client stack drives one), and a field of
view that looks like radians: `hfov_deg: 1.5708` is a legal 1.6° camera, but far more often a
90° one written in radians (a trial user's scenario); refusing it would refuse the rare
telephoto lens, and saying nothing leaves a dataset of sky to be found afterwards. And entries
of the timeline and of scripts after the run's end (late_settings, late_steps): taken, since a
sweep's `--duration` may cut a file short on purpose, but said. And a copy of a bundled
elevation image (`bay.png`, copied to edit it): it silently lost the scale its bundled
`bay.json` gives (2 m a pixel, not the defaults' 5), a bay 2.5 times wider.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

from catabot.config import live
from catabot.config.load import TERRAINS
from catabot.config.scenario import Scenario

FIELDS_OF_VIEW = ("hfov_deg", "vertical_fov_deg")


def scenario_notes(scenario: Scenario) -> list[str]:
    """Every note, said by `scenario validate` and before a run alike."""
    return [*shared_notes(scenario), *angle_notes(scenario), *terrain_notes(scenario)]


def shared_notes(scenario: Scenario) -> list[str]:
    """A participant given several vessels is allowed (a stack on the bus itself publishes
    each one's commands), but `catabot.client`'s join() commands one vessel and refuses it:
    said before the run, not after a start timeout."""
    driven: dict[str, list[str]] = {}
    for vessel in scenario.vessels:
        if vessel.controller is not None:
            driven.setdefault(vessel.controller.participant, []).append(vessel.id)
    return [_shared_note(name, ids) for name, ids in driven.items() if len(ids) > 1]


def _shared_note(name: str, ids: list[str]) -> str:
    return (f"note: participant {name!r} controls vessels {', '.join(ids)}: a catabot.client "
            "stack commands one vessel per participant (give each its own "
            "controller.participant; one process may join several), only a stack on the bus "
            "itself can drive them together")  # fmt: skip


def angle_notes(scenario: Scenario) -> list[str]:
    """A field of view in degrees no wider than 2π: radians, most likely."""
    notes = []
    for v, vessel in enumerate(scenario.vessels):
        for s, sensor in enumerate(vessel.sensors):
            params = sensor.typed_params()
            for name in FIELDS_OF_VIEW:
                value = getattr(params, name, None)
                if isinstance(value, float) and value <= math.tau:
                    notes.append(
                        f"note: vessels.{v}.sensors.{s}.params.{name} ({vessel.id}/{sensor.name})"
                        f" is {value:g} degrees; if it is radians, that is "
                        f"{math.degrees(value):.4g} degrees: give that"
                    )
    return notes


SCALE_FIELDS = ("metres_per_pixel", "min_elevation_m", "max_elevation_m")


def terrain_notes(scenario: Scenario) -> list[str]:
    """A copy of a bundled image (`bay.png`, to edit it) whose scale is not the bundled
    one's: a bare name the scenario's folder has is that file, and the bundled scale file
    only comes with the bundled image."""
    terrain = scenario.terrain
    original = _bundled_original(Path(terrain.elevation_image)) if terrain else None
    if terrain is None or original is None:
        return []
    own = json.loads(original.with_suffix(".json").read_text())
    if all(getattr(terrain, k) == own.get(k, getattr(terrain, k)) for k in SCALE_FIELDS):
        return []
    now = ", ".join(f"{k} {getattr(terrain, k):g}" for k in SCALE_FIELDS)
    scale = ", ".join(f"{k} {own[k]:g}" for k in SCALE_FIELDS if k in own)
    return [f"note: terrain.elevation_image {terrain.elevation_image} is a copy of the bundled "
            f"{original.name}, whose scale ({scale}) comes in {original.stem}.json beside it; "
            f"this run's is {now}: give the terrain those fields if the copy is to be the "
            "same bay"]  # fmt: skip


def _bundled_original(image: Path) -> Path | None:
    """The bundled image with a scale file that `image` is a byte-for-byte copy of."""
    if not image.is_file() or image.resolve().parent == TERRAINS.resolve():
        return None  # the bundled image itself: its scale is the scenario's to change
    size = image.stat().st_size
    for bundled in sorted(TERRAINS.glob("*.png")):
        same_size = bundled.stat().st_size == size and bundled.with_suffix(".json").is_file()
        if same_size and bundled.read_bytes() == image.read_bytes():
            return bundled
    return None


def late_settings(scenario: Scenario) -> list[str]:
    """Timeline entries after the run's last tick (a `--duration` shorter than the file's):
    taken, never applied. Said by `scenario validate` and by the conductor at a run."""
    last = live.last_tick_s(scenario)
    return [f"settings.{i} ({s.key} at {s.t_s:g} s) comes after the run's last tick "
            f"({last:g} s), so it never applies"
            for i, s in enumerate(scenario.settings)
            if live.after_end(scenario, s.t_s)]  # fmt: skip


def late_steps(scenario: Scenario) -> list[str]:
    """Script steps after the run's last tick: said by `scenario validate` and physics."""
    last = live.last_tick_s(scenario)
    return [f"{v.id}: its script step at {step.t_s:g} s comes after the run's last tick "
            f"({last:g} s), so it is never applied"
            for v in scenario.vessels for step in v.script
            if live.after_end(scenario, step.t_s)]  # fmt: skip
