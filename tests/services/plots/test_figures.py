"""What the figures draw from a run's scenario: the rain rate as the run had it."""

from __future__ import annotations

import numpy as np

from catabot.config.load import parse_scenario
from services.plots.figures import rain_steps


def test_the_rain_rate_follows_the_settings_timeline() -> None:
    """`catabot set rain 25` (written back into the run's scenario.json as a timeline entry)
    was drawn as the scenario's starting rate for the whole run."""
    scenario = parse_scenario({
        "name": "wet", "duration_s": 10.0, "rain": {"rate_mm_h": 5.0},
        "vessels": [{"id": "ego"}],
        "settings": [{"t_s": 6.0, "key": "rain", "value": 0}, {"t_s": 2.5, "key": "rain",
                     "value": 25}, {"t_s": 3.0, "key": "waves", "value": "heavy"}],
    })  # fmt: skip
    t, rate = rain_steps(scenario, 10.0)
    assert t.tolist() == [0.0, 2.5, 6.0, 10.0] and rate.tolist() == [5.0, 25.0, 0.0, 0.0]
    at = rate[np.searchsorted(t, [0.0, 2.4, 2.5, 7.0], side="right") - 1]
    assert at.tolist() == [5.0, 5.0, 25.0, 0.0]


def test_without_changes_the_rain_is_the_scenarios() -> None:
    scenario = parse_scenario({"name": "dry", "duration_s": 4.0, "vessels": [{"id": "ego"}]})
    t, rate = rain_steps(scenario, 4.0)
    assert t.tolist() == [0.0, 4.0] and rate.tolist() == [0.0, 0.0]
