"""report.html's summary table (services/plots/report.py)."""

from __future__ import annotations

from types import SimpleNamespace
from typing import Any

from services.plots.report import _ended


def _series(metrics: dict[str, Any] | None) -> Any:
    scenario = SimpleNamespace(duration_s=30.0)
    return SimpleNamespace(
        metrics=metrics, run=SimpleNamespace(world=SimpleNamespace(scenario=scenario))
    )


def test_an_interrupted_run_says_so() -> None:
    """Its report read as a whole run's: "simulated 4.84 s" of a 30 s scenario, no word why."""
    assert _ended(_series({"end_reason": "interrupted"})) == "interrupted, of 30 s planned"
    assert _ended(_series({"end_reason": "completed"})) == "completed"
    assert _ended(_series(None)) == "completed"  # no metrics.json: nothing says otherwise
