"""`catabot plot RUN_FOLDER [-o OUT_DIR]`: PNG figures and `report.html` of a recorded run;
`catabot plot RUN RUN ...` or a folder of runs: their scenario vessels compared (compare.py).

Trajectories over the terrain with the traffic and buoys, speed and heading, thrust and
twist commands, IMU series, LiDAR returns and rain returns against the rain rate, and the
navigation metrics; written to OUT_DIR (default RUN_FOLDER/plots). Exit codes: 0 written,
2 refused (no such run folder, no run.mcap), with one line saying why.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from catabot.errors import CataBotError
from catabot.run.answer import OneLineParser, answered, output_folder
from catabot.run.folders import is_run, run_folders
from catabot.run.recorded import RecordedRun, RunFolderError
from services.plots import compare, report, series
from services.plots.figures import FIGURES

PNG = {"Software": None}  # no version string: the same run gives the same bytes


def parser() -> argparse.ArgumentParser:
    p = OneLineParser(prog="catabot plot", description=__doc__.split("\n")[0])
    p.add_argument("run", nargs="+", help="the run folder (runs/<world>-<time>); several, or "
                   "a folder of runs: their vessels compared on one set of axes")  # fmt: skip
    p.add_argument("--output", "-o", help="folder for the PNGs and report.html (compared: "
                   "compare.html; default RUN/plots, the first RUN's compare/, or the folder "
                   "of runs' compare/)")  # fmt: skip
    return p


def plot(run_folder: str, out: Path | None) -> Path:
    data = series.read(RecordedRun(run_folder))
    out = out or data.run.folder / "plots"
    out.mkdir(parents=True, exist_ok=True)
    written: dict[str, str | None] = {}
    for name, draw in FIGURES.items():
        fig = draw(data)
        written[name] = None if fig is None else f"{name}.png"
        if fig is not None:
            fig.savefig(out / f"{name}.png", metadata=PNG)
    report.write(out / "report.html", data, written)
    return out


def plot_compared(folders: list[str], out: Path | None) -> str:
    runs = []
    for folder in folders:  # one unusable folder (no tick, not a run) need not stop the rest
        try:
            runs.append(series.read(RecordedRun(folder), full=False))
        except CataBotError as exc:
            print(f"catabot plot: left out: {exc}", file=sys.stderr)
    if not runs:
        raise RunFolderError("no run to compare: every folder given was left out (above)")
    out = out or runs[0].run.folder / "compare"
    out.mkdir(parents=True, exist_ok=True)
    files = {}
    for name, fig in compare.figures(runs).items():
        fig.savefig(out / f"{name}.png", metadata=PNG)
        files[name] = f"{name}.png"
    compare.report(out / "compare.html", runs, files)
    return f"{len(runs)} run{'' if len(runs) == 1 else 's'} compared in {out}"


def main(argv: list[str] | None = None) -> int:
    args = parser().parse_args(argv)
    try:
        out, runs = _out(args.output), expanded(args.run)
    except CataBotError as exc:
        print(f"catabot plot: {exc}", file=sys.stderr)
        return 2
    if runs != args.run and len(args.run) == 1:  # a sweep's folder: compare/ beside its runs
        out = out or Path(args.run[0]) / "compare"
    if len(runs) > 1:
        return answered("plot", lambda: plot_compared(runs, out))
    return answered("plot", lambda: f"plots and report.html in {plot(runs[0], out)}")


def expanded(paths: list[str]) -> list[str]:
    """A folder of runs (a sweep's --out) as the runs in it, as `catabot results` takes it;
    a run folder, or anything else (named by the reader if it is not a run), as given."""
    out: list[str] = []
    for path in paths:
        folder = Path(path)
        inner = folder.is_dir() and not is_run(folder)
        out += [str(f) for f in run_folders([path])] if inner else [path]
    return out


def _out(output: str | None) -> Path | None:
    return output_folder(output, flag="-o") if output is not None else None


if __name__ == "__main__":
    sys.exit(main())
