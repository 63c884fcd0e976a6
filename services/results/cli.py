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
from typing import Any, TextIO

from catabot.config.base import ConfigError
from catabot.config.differences import one_scenario
from catabot.run.answer import OneLineParser, answered, output_file
from catabot.run.folders import RunFoldersError, run_folders
from services.results import rows

SHOWN = ("seed", "reason", "goal_reached", "time_to_goal_s", "nearest_vessel_m",
         "nearest_buoy_m", "nearest_shore_m", "collisions", "groundings", "thrust_impulse_Ns",
         "thrust_unknown_s")  # fmt: skip
ALWAYS = {"run", "vessel", "seed", "reason"}  # the others shown where any row has a value


def parser() -> argparse.ArgumentParser:
    p = OneLineParser(prog="catabot results", description=__doc__.split("\n")[0])
    p.add_argument("runs", nargs="+", metavar="RUN",
                   help="run folders, or folders of runs (a sweep's --out)")  # fmt: skip
    p.add_argument(
        "--csv",
        metavar="FILE",
        help="also write every column to this CSV file "
        "(- : the CSV on stdout instead of the table)",
    )
    return p


def main(argv: list[str] | None = None) -> int:
    args = parser().parse_args(argv)
    return answered("results", lambda: results(args.runs, args.csv))


def results(paths: list[str], csv_path: str | None) -> str:
    """`--csv -`: the CSV on stdout instead of the console table, the count on stderr (it
    wrote a file named "-")."""
    piped = csv_path == "-"
    out = output_file(csv_path, flag="--csv") if csv_path and not piped else None  # first
    records = _readable(run_folders(paths))
    _mixed(records)
    _versions(records)
    header, table = rows.table(records)
    if piped:
        _csv_rows(sys.stdout, header, table)
        print(f"{_count(len(records), 'run')}, {_count(len(table), 'row')}", file=sys.stderr)
        return ""
    print(text_table(header, table))
    if out is not None:
        write_csv(out, header, table)
    written = f"; every column in {out}" if out else ""
    return f"{_count(len(records), 'run')}, {_count(len(table), 'row')}{written}"


def _count(n: int, what: str) -> str:
    return f"{n} {what}" + ("" if n == 1 else "s")


def _mixed(records: list[rows.RunRecord]) -> None:
    """Runs of different scenarios compare field by field, list items by position (a
    sensor's noise against another's): said, since the table's columns are then not a sweep."""
    first = records[0].scenario
    if not all(one_scenario(first, r.scenario) for r in records):
        names = sorted({r.scenario.name for r in records})
        print(f"catabot results: runs of {len(names)} scenarios ({', '.join(names)}): their "
              "differences are field by field; tabulate each scenario's runs apart for a "
              "sweep's columns", file=sys.stderr)  # fmt: skip


def _versions(records: list[rows.RunRecord]) -> None:
    """Runs of different commits (a sweep run while the code changed): said, as their
    differences may be the code's; the CSV's git_commit column says which is which."""
    commits = sorted({str(r.run.get("git_commit")) for r in records if r.run})
    if len(commits) > 1:
        print(f"catabot results: runs of {len(commits)} versions of the code ("
              f"{', '.join(c[:12] for c in commits)}): see the CSV's git_commit column",
              file=sys.stderr)  # fmt: skip


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
        raise RunFoldersError("no run to tabulate: every folder found was left out (above)")
    return records


def text_table(header: list[str], table: list[dict[str, Any]]) -> str:
    """The run, vessel, swept and main measured columns, aligned; blank where not measured."""
    swept = header[2 : header.index(rows.RUN_COLUMNS[0])]
    shown = [c for c in SHOWN if c in ALWAYS or any(_measured(c, r.get(c)) for r in table)]
    columns = ["run", "vessel", *swept, *shown]
    cells = [columns, *([_shown(r.get(c), set_as=c in swept) for c in columns] for r in table)]
    widths = [max(len(line[i]) for line in cells) for i in range(len(columns))]
    return "\n".join("  ".join(c.ljust(w) for c, w in zip(line, widths, strict=True)).rstrip()
                     for line in cells)  # fmt: skip


def _measured(column: str, value: Any) -> bool:
    """A value worth a console column: not blank, and for the time under velocity control
    (a caveat to the thrust impulse), not zero."""
    return value is not None and (column != "thrust_unknown_s" or bool(value))


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
        _csv_rows(f, header, table)


def _csv_rows(f: TextIO, header: list[str], table: list[dict[str, Any]]) -> None:
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
