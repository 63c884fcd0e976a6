"""Notes on a valid scenario that is likely not what its author meant, said before the run.

Why: `hfov_deg: 1.5708` is a legal 1.6° camera, but it is far more often a 90° one written
in radians (a trial user's scenario); refusing it would refuse the rare telephoto lens, and
saying nothing leaves a dataset of sky to be found afterwards.
"""

from __future__ import annotations

import math

from catabot.config.scenario import Scenario

FIELDS_OF_VIEW = ("hfov_deg", "vertical_fov_deg")


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
