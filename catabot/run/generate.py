"""`catabot scenario generate`: a valid traffic scenario from a few flags.

The file it writes is an ordinary scenario (validated before it is written), so a
generated run can be edited, versioned and replayed like any hand-written one.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from typing import Any

from catabot.config.load import absolute_paths, parse_scenario, with_sets
from catabot.config.traffic import BEHAVIOURS
from catabot.errors import CataBotError
from catabot.run.answer import answered, output_file
from catabot.world.world import World


class GenerateError(CataBotError, ValueError):
    """Flags that cannot make a scenario; the message names the flag."""


def parse_mix(text: str) -> dict[str, float]:
    """`circle=0.5,waypoints=0.5` → {"circle": 0.5, "waypoints": 0.5}."""
    mix: dict[str, float] = {}
    for part in filter(None, text.split(",")):
        name, _, weight = part.partition("=")
        if name.strip() not in BEHAVIOURS:
            raise GenerateError(
                f"--mix: unknown behaviour {name!r} (allowed: {', '.join(BEHAVIOURS)})"
            )
        if name.strip() in mix:  # the last one was kept, silently
            raise GenerateError(f"--mix: {name.strip()!r} given twice")
        try:
            mix[name.strip()] = float(weight)
        except ValueError:
            raise GenerateError(f"--mix: weight of {name!r} is not a number ({weight!r})") from None
    if not mix:
        raise GenerateError("--mix: give at least one behaviour=weight")
    return mix


def scenario_data(args: argparse.Namespace) -> dict[str, Any]:
    mix = parse_mix(given(args, "mix"))
    data: dict[str, Any] = {
        "name": given(args, "name"),
        "seed": given(args, "seed"),
        "duration_s": given(args, "duration"),
        "vessels": [{"id": "ego", "model": "catabot"}],
        "traffic": {"count": given(args, "boats"), "behaviour_mix": mix},
    }
    if args.terrain:  # from the current directory, or a bundled one named bare
        data["terrain"] = {"elevation_image": args.terrain}  # a bundled one: its own scale
    return absolute_paths(data, Path.cwd())


def _with_sets(args: argparse.Namespace, data: dict[str, Any]) -> tuple[dict[str, Any], str]:
    """`--set`'s changes made to what the flags made (they were taken and dropped), a field
    that a flag given also sets refused; paths from the current folder, as the flags'."""
    if not args.set:
        return data, "from the flags"
    flagged = {f: f"--{flag}" for flag, f in FLAG_FIELDS.items() if getattr(args, flag) is not None}
    flags = with_sets(data, list(args.set), source="from the flags", flagged=flagged)
    return absolute_paths(data, Path.cwd()), f"from the flags with {' '.join(flags)}"


DEFAULTS = {"boats": 10, "mix": "circle=1", "seed": 0, "duration": 60.0, "name": "traffic"}
FLAG_FIELDS = {"name": "name", "seed": "seed", "duration": "duration_s", "boats": "traffic.count",
               "mix": "traffic.behaviour_mix", "terrain": "terrain.elevation_image"}  # fmt: skip
ONLY_GENERATE = ("boats", "mix", "terrain", "name")  # `validate` takes --seed and --duration


def add_arguments(p: argparse.ArgumentParser) -> None:
    """The flags default to None, so `scenario validate` can tell a flag it was given (and
    refuse the ones that are generate's alone) from one it was not."""
    p.add_argument("--boats", type=int, help="generate: traffic boats (0-500; default 10)")
    p.add_argument("--mix", help="generate: behaviour weights (default circle=1), e.g. "
                   "circle=0.5,waypoints=0.5")  # fmt: skip
    p.add_argument("--seed", type=int, help="the seed (generate: default 0)")
    p.add_argument("--terrain", help="generate: elevation image (PNG) for the terrain")
    p.add_argument("--duration", type=float, help="simulated seconds (generate: default 60)")
    p.add_argument("--name", help="generate: world name (default traffic)")


def given(args: argparse.Namespace, flag: str) -> Any:
    """A generate flag's value, or its default."""
    value = getattr(args, flag)
    return DEFAULTS[flag] if value is None else value


def generate(args: argparse.Namespace) -> int:
    """Write the scenario to args.output (stdout when none); 2 on a bad flag or scenario."""
    return answered("scenario generate", lambda: _write(args))


def _write(args: argparse.Namespace) -> str | None:
    output = output_file(args.output, flag="--output") if args.output else None
    data, source = _with_sets(args, scenario_data(args))
    scenario = parse_scenario(data, source=source)
    World.resolve(scenario)  # refuse what cannot run
    text = json.dumps(data, indent=2) + "\n"
    if output is None:
        sys.stdout.write(text)
        return None
    output.write_text(text)
    return f"{args.output}: {scenario.traffic.count} boat(s), seed {scenario.seed}"  # --set's
