"""`catabot results RUN_OR_FOLDER ... [--csv FILE]`: many runs in one table, for sweeps.

A row per run and scenario vessel: the scenario fields the runs differ in (each a column,
named as `--set` names it), the seed, how the run ended, and the vessel's metrics (goal,
nearest bodies, contacts, thrust). A folder of runs (`catabot run --out runs/sweep`, many
times) stands for every run in it. The console gets the main columns; `--csv` writes all
of them, numbers as numbers (pandas reads a measured column as float). Exit codes: 0, or 2
with one line saying why (no such folder, no run in it, an unwritable file).
"""

from __future__ import annotations

import argparse
import csv
import json
import sys
from pathlib import Path
from typing import Any

from catabot.config.base import ConfigError
from catabot.run.answer import OneLineParser, answered, output_file
from services.results import folders, rows
from services.results.folders import ResultsError

SHOWN = ("seed", "reason", "goal_reached", "time_to_goal_s", "nearest_vessel_m", "collisions",
         "groundings", "thrust_impulse_Ns")  # fmt: skip


def parser() -> argparse.ArgumentParser:
    p = OneLineParser(prog="catabot results", description=__doc__.split("\n")[0])
    p.add_argument("runs", nargs="+", metavar="RUN",
                   help="run folders, or folders of runs (a sweep's --out)")  # fmt: skip
    p.add_argument("--csv", metavar="FILE", help="also write every column to this CSV file")
    return p


def main(argv: list[str] | None = None) -> int:
    args = parser().parse_args(argv)
    return answered("results", lambda: results(args.runs, args.csv))


def results(paths: list[str], csv_path: str | None) -> str:
    out = output_file(csv_path, flag="--csv") if csv_path else None  # before reading runs
    records = _readable(folders.run_folders(paths))
    header, table = rows.table(records)
    print(text_table(header, table))
    if out is not None:
        write_csv(out, header, table)
    written = f"; every column in {out}" if out else ""
    return f"{len(records)} runs, {len(table)} rows{written}"


def _readable(found: list[Path]) -> list[rows.RunRecord]:
    """Every run whose scenario reads; the others left out, each named (one broken folder
    need not hide a sweep)."""
    records = []
    for folder in found:
        try:
            records.append(rows.read(folder))
        except ConfigError as exc:
            print(f"catabot results: left out {folder}: {exc}".splitlines()[0], file=sys.stderr)
    if not records:
        raise ResultsError("no run to tabulate: every folder found was left out (above)")
    return records


def text_table(header: list[str], table: list[dict[str, Any]]) -> str:
    """The run, vessel, swept and main measured columns, aligned; blank where not measured."""
    swept = header[2 : header.index(rows.RUN_COLUMNS[0])]
    columns = ["run", "vessel", *swept, *SHOWN]
    cells = [columns, *([_shown(r.get(c), set_as=c in swept) for c in columns] for r in table)]
    widths = [max(len(line[i]) for line in cells) for i in range(len(columns))]
    return "\n".join("  ".join(c.ljust(w) for c, w in zip(line, widths, strict=True)).rstrip()
                     for line in cells)  # fmt: skip


def _shown(value: Any, *, set_as: bool = False) -> str:
    """A measured number to 0.01; a swept field's value as it was set (a gain of 0.005 is
    not 0.01)."""
    if value is None:
        return "-"
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, float) and not set_as:
        return f"{value:.2f}"
    return value if isinstance(value, str) else json.dumps(value)


def write_csv(path: Path, header: list[str], table: list[dict[str, Any]]) -> None:
    with path.open("w", newline="") as f:
        writer = csv.writer(f, lineterminator="\n")
        writer.writerow(header)
        writer.writerows([_cell(r.get(c)) for c in header] for r in table)


def _cell(value: Any) -> Any:
    """A number as itself (a float keeps its point: `12.0`), a list or object as JSON, blank
    for nothing."""
    if value is None:
        return ""
    if isinstance(value, list | dict):
        return json.dumps(value)
    return value
