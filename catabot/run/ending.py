"""How a recorded run ended, read from its folder: one rule for every tool (the plots'
report and comparison, `catabot results`, the dataset export, the live view)."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

KILLED = "killed (log/run.json has no ending)"
RUNNING = "running"
"""The reason in the `log/run.json` written when a run starts (provenance.py), until its
end rewrites it: a folder whose run is gone and still says so was killed outright."""


def run_record(folder: Path) -> dict[str, Any] | None:
    """A run folder's `log/run.json` (the launcher's account), None where there is none;
    one of a run still going, or killed outright, has `reason` RUNNING (`finished`)."""
    try:
        record = json.loads((folder / "log" / "run.json").read_text())
    except (OSError, ValueError):
        return None
    return record if isinstance(record, dict) else None


def finished(record: dict[str, Any] | None) -> bool:
    """Whether a `run_record` tells how its run ended."""
    return record is not None and record.get("reason") not in (None, "", RUNNING)


def end_reason(run: dict[str, Any] | None, metrics: dict[str, Any] | None) -> str:
    """Why a run ended, the one rule every tool reads it by: its `log/run.json`'s reason,
    else its `metrics.json`'s (a recorder's account), else neither was written: killed."""
    told = (run or {}).get("reason") if finished(run) else None
    return str(told or (metrics or {}).get("end_reason") or KILLED)
