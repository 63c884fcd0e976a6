"""Where scenarios differ, field by field: what tells the runs of a sweep apart.

`catabot plot RUN RUN ...` names each run by its differences from the first, and `catabot
results` gives each swept field a column (and the timelines one, `settings`, where they
differ). Both read them here, so a field is spelled the same in a plot's legend, a table's
header and `catabot run --set` (`water.current.velocity_mps`, `vessels.0.pose.x_m`).
"""

from __future__ import annotations

import json
from typing import Any

from catabot.config.scenario import Scenario

NOT_SWEPT = {"name", "settings"}  # a run's own name; its timeline is told on its own
FEW = 6  # fields: runs this close are one scenario's, whatever their names


def flat_fields(scenario: Scenario) -> dict[str, Any]:
    """Every field of the scenario as `a.b.0.c: value` leaves, JSON values."""
    return flatten(scenario.model_dump(mode="json", exclude=NOT_SWEPT))


def flatten(tree: Any, prefix: str = "") -> dict[str, Any]:
    """A nested tree as dotted leaves. A list of plain values is one value (a current's
    [east, north]); a list holding objects is indexed (`vessels.0`)."""
    if isinstance(tree, list) and any(isinstance(v, dict | list) for v in tree):
        tree = dict(enumerate(tree))
    if not isinstance(tree, dict):
        return {prefix: tree}
    out: dict[str, Any] = {}
    for key, value in tree.items():
        out |= flatten(value, f"{prefix}.{key}" if prefix else str(key))
    return out


def timeline(scenario: Scenario) -> list[str]:
    """Its settings timeline, an entry each (`current=[0.0, 0.5] at 2 s`): a plot's legend
    and the results' `settings` column spell it alike."""
    return [f"{c.key}={json.dumps(c.value)} at {c.t_s:g} s" for c in scenario.settings]


def differences(first: Scenario, other: Scenario) -> dict[str, Any]:
    """The fields of `other` whose value is not the one in `first`, with `other`'s value,
    in name order."""
    base, own = flat_fields(first), flat_fields(other)
    return {k: own[k] for k in sorted(own) if own[k] != base.get(k)}


def swept_fields(scenarios: list[Scenario]) -> list[str]:
    """The fields in which any of the scenarios differs from the first (either way: a field
    only the first has counts too), in name order."""
    base, keys = flat_fields(scenarios[0]), set()
    for own in map(flat_fields, scenarios[1:]):
        keys |= {k for k in own.keys() | base.keys() if own.get(k) != base.get(k)}
    return sorted(keys)


def one_scenario(first: Scenario, other: Scenario) -> bool:
    """Runs of one scenario: the same name, or few fields apart (a sweep that names each run
    with `--set name=...`). Runs of others compare field by field, list items by position."""
    return other.name == first.name or len(differences(first, other)) <= FEW
