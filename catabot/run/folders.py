"""Which folders are runs: the ones named, or the runs inside a folder of runs.

A sweep writes its runs into one folder (`catabot run --out runs/sweep`, a run each in
`runs/sweep/<name>-<time>`), so naming that folder names them all, in name order (the
order they were started in, since the time is in the name). `catabot results` and `catabot
plot` take folders alike.
"""

from __future__ import annotations

from pathlib import Path

from catabot.errors import CataBotError


class RunFoldersError(CataBotError, ValueError):
    """A folder that is neither a run nor holds any."""


def is_run(folder: Path) -> bool:
    """A run folder: `catabot run` writes its scenario.json first."""
    return (folder / "scenario.json").is_file()


def run_folders(paths: list[str]) -> list[Path]:
    """Each path as the runs it names, once each (one folder spelled two ways, `tl` and
    `/abs/tl`, had given each run twice), in the order given."""
    found: list[Path] = []
    for path in paths:
        seen = {f.resolve() for f in found}
        found += [f for f in _runs_in(Path(path)) if f.resolve() not in seen]
    return found


def _runs_in(path: Path) -> list[Path]:
    if not path.exists():
        raise RunFoldersError(f"{path}: no such folder")
    if not path.is_dir():
        raise RunFoldersError(f"{path}: a file; give a run folder or a folder of runs")
    if is_run(path):
        return [path]
    inside = sorted(f for f in path.iterdir() if f.is_dir() and is_run(f))
    if not inside:
        raise RunFoldersError(
            f"{path}: not a run folder (it has no scenario.json), and no run folder in it"
        )
    return inside
