"""`catabot plot RUN_FOLDER [-o OUT_DIR]`: PNG figures and `report.html` of a recorded run;
`catabot plot RUN RUN ...`: their scenario vessels compared (compare.py).

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
from catabot.run.recorded import RecordedRun, RunFolderError
from services.plots import compare, report, series
from services.plots.figures import FIGURES

PNG = {"Software": None}  # no version string: the same run gives the same bytes


def parser() -> argparse.ArgumentParser:
    p = OneLineParser(prog="catabot plot", description=__doc__.split("\n")[0])
    p.add_argument("run", nargs="+", help="the run folder (runs/<world>-<time>); several: "
                   "their scenario vessels compared on one set of axes")  # fmt: skip
    p.add_argument("--output", "-o", help="folder for the PNGs and report.html (compared: "
                   "compare.html; default RUN/plots, or the first RUN's compare/)")  # fmt: skip
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
    return f"{len(runs)} runs compared in {out}"


def main(argv: list[str] | None = None) -> int:
    args = parser().parse_args(argv)
    try:
        out = _out(args.output)
    except CataBotError as exc:
        print(f"catabot plot: {exc}", file=sys.stderr)
        return 2
    if len(args.run) > 1:
        return answered("plot", lambda: plot_compared(args.run, out))
    return answered("plot", lambda: f"plots and report.html in {plot(args.run[0], out)}")


def _out(output: str | None) -> Path | None:
    return output_folder(output, flag="-o") if output is not None else None


if __name__ == "__main__":
    sys.exit(main())
