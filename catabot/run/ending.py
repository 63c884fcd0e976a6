"""How a recorded run ended, read from its folder: one rule for every tool (the plots'
report and comparison, `catabot results`, the dataset export, the live view)."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

KILLED = "killed (no log/run.json)"


def run_record(folder: Path) -> dict[str, Any] | None:
    """A run folder's `log/run.json` (the launcher's account), None where there is none:
    a run killed outright, or still going."""
    try:
        record = json.loads((folder / "log" / "run.json").read_text())
    except (OSError, ValueError):
        return None
    return record if isinstance(record, dict) else None


def end_reason(run: dict[str, Any] | None, metrics: dict[str, Any] | None) -> str:
    """Why a run ended, the one rule every tool reads it by: its `log/run.json`'s reason,
    else its `metrics.json`'s (a recorder's account), else neither was written: killed."""
    return str((run or {}).get("reason") or (metrics or {}).get("end_reason") or KILLED)
