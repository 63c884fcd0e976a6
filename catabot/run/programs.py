"""Autonomy stacks `catabot run` starts itself: `vessels[].controller.program`.

A controller with a `program` is one more process of the run, supervised like a service
(its stdout and stderr in `log/<participant>.log`, killed and named on faults, counted in
the summary). It is started as `python PROGRAM <flags> <args>` with the flags every
example parses (catabot/bus/session.py, examples/common.py) plus its name and vessel:

    --connect ENDPOINT [--mode client]   this run's Zenoh (the conductor, or the router)
    --zid ZID                            the session id the run's roster gives it
    --world NAME --vessel ID             the key prefix catabot/<NAME>/ and its (first) vessel
    --participant NAME                   its name in the lockstep (controller.participant)
    [--zenoh-config FILE]                its login, in the secure profile (--secure)

and in its environment CATABOT_SCENARIO (the run folder's resolved scenario.json) and
CATABOT_RUN_DIR. Its session id is in every service's roster, so nothing but that process
can step or command as that participant.
"""

from __future__ import annotations

import os
import sys
from dataclasses import dataclass
from pathlib import Path

from catabot.config.scenario import Scenario
from catabot.errors import CataBotError


class ProgramError(CataBotError, RuntimeError):
    """A controller's program cannot be started (it is not a file)."""


@dataclass(frozen=True)
class Program:
    participant: str
    vessel: str  # the first vessel it controls
    path: Path
    args: tuple[str, ...]


def programs(scenario: Scenario, source: str | None) -> list[Program]:
    """The programs to start, one per participant (the scenario checked that a participant
    has one program and one set of args); ProgramError names a controller whose program is
    not a file (load_scenario made it absolute when it found it)."""
    found: dict[str, Program] = {}
    for index, vessel in enumerate(scenario.vessels):
        c = vessel.controller
        if c is None or c.program is None or c.participant in found:
            continue
        path = Path(c.program)
        if not path.is_file():
            where = Path(source).resolve().parent if source else Path.cwd()
            raise ProgramError(
                f"vessels.{index}.controller.program: {c.program!r} is not a file (looked in "
                f"{where} and in the current directory {Path.cwd()})"
            )
        found[c.participant] = Program(c.participant, vessel.id, path, tuple(c.args))
    return list(found.values())


def command(program: Program, world: str, flags: list[str]) -> list[str]:
    """The program's command line: `flags` are its connection, zid and login flags."""
    return [
        sys.executable,
        str(program.path),
        *flags,
        *("--world", world, "--vessel", program.vessel, "--participant", program.participant),
        *program.args,
    ]


def environment(run_dir: Path) -> dict[str, str]:
    """The launcher's environment, unbuffered (lines reach the log as they are written), with
    where the run's files are."""
    return os.environ | {
        "PYTHONUNBUFFERED": "1",
        "CATABOT_SCENARIO": str(run_dir / "scenario.json"),
        "CATABOT_RUN_DIR": str(run_dir),
    }
