"""What produced a run, for `log/run.json`: the command line, the scenario's name and seed,
CataBot's version and commit, and a hash of each controller program.

Why: "same scenario and seed, same bytes" could not be checked from a run folder alone: it
held the scenario but not the code that ran it, nor the program that drove a vessel (its
path only), and a sweep's table had to join three files to label a row with its seed.
"""

from __future__ import annotations

import hashlib
import json
import os
import subprocess
import sys
from datetime import datetime
from importlib import metadata
from pathlib import Path
from typing import Any

from catabot.config.scenario import Scenario
from catabot.run.ending import RUNNING

PACKAGE = Path(__file__).resolve().parents[2]  # the source tree (a git work tree, if cloned)


def provenance(scenario: Scenario) -> dict[str, Any]:
    return {
        "scenario": scenario.name,
        "seed": scenario.seed,
        "command": ["catabot", *sys.argv[1:]],
        "catabot_version": _version(),
        "git_commit": _commit(),
        "programs": _programs(scenario),
    }


def write_started(run_dir: Path, scenario: Scenario, *, writer: str = "launcher") -> None:
    """`log/run.json` as the run starts: its reason RUNNING, when and by which process, and
    the provenance, so a run killed outright (SIGKILL, a machine lost) still says what it
    was; the launcher's account replaces it at the end (summary.py), or in a split run the
    recorder's (services/recorder/split_record.py)."""
    record = {"reason": RUNNING, "started": datetime.now().astimezone().isoformat(),
              f"{writer}_pid": os.getpid(), **provenance(scenario)}  # fmt: skip
    (run_dir / "log" / "run.json").write_text(json.dumps(record, indent=2) + "\n")


def _version() -> str:
    try:
        return metadata.version("catabot")
    except metadata.PackageNotFoundError:
        return ""


def _commit() -> str:
    """The source tree's commit, with `+dirty` when it has changes; "" outside a clone."""
    try:
        head = _git("rev-parse", "HEAD")
        dirty = bool(_git("status", "--porcelain", "--untracked-files=no"))
    except (OSError, subprocess.SubprocessError):
        return ""
    return head + ("+dirty" if dirty else "") if head else ""


def _git(*args: str) -> str:
    done = subprocess.run(["git", "-C", str(PACKAGE), *args], capture_output=True, text=True,
                          timeout=5, check=True)  # fmt: skip
    return done.stdout.strip()


def _programs(scenario: Scenario) -> dict[str, dict[str, str]]:
    """Each controller program's path and SHA-256 (what drove its vessel, as it is now)."""
    out: dict[str, dict[str, str]] = {}
    for vessel in scenario.vessels:
        c = vessel.controller
        if c is None or c.program is None or c.participant in out:
            continue
        try:
            digest = hashlib.sha256(Path(c.program).read_bytes()).hexdigest()
        except OSError:
            digest = ""
        out[c.participant] = {"path": c.program, "sha256": digest}
    return out
