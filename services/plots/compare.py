"""`catabot plot RUN RUN ...`: several runs' scenario vessels on one set of axes.

Why: a lab compares a controller in calm water with the same in a current, a sweep a gain's
values; one run's plots each, side by side, do not show the difference. The runs are told
apart by colour (named by their folders, and by the settings that differ between them), each
vessel of a run by its line style; `compare.html` has every run's figures in one table.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib import colormaps
from matplotlib.figure import Figure

from catabot.config.differences import flat_fields, one_scenario, swept_fields, timeline
from services.plots.figures import draw_task, speed_heading_axes, task_points
from services.plots.report import table_row, vessel_cells
from services.plots.series import RunSeries

STYLES = ["-", "--", ":", "-."]
COLORS = colormaps["tab20"]  # 20 runs apart by colour
SAME_M = 0.01  # tracks this close at every sample are one track drawn twice


def figures(runs: list[RunSeries]) -> dict[str, Figure]:
    labels = run_labels(runs)
    return {"compare_trajectories": _tracks(runs, labels),
            "compare_speed_heading": _speed_heading(runs, labels)}  # fmt: skip


def run_labels(runs: list[RunSeries]) -> list[str]:
    """Each run's folder name, its value of every field the runs of the first run's scenario
    differ in (the first run's too: a paper's legend names every case), its setting changes,
    and how it ended unless it completed; a run of another scenario, that scenario's name."""
    first = runs[0].run.world.scenario
    kin = [one_scenario(first, d.run.world.scenario) for d in runs]
    swept = swept_fields([d.run.world.scenario for d, k in zip(runs, kin, strict=True) if k])
    return [d.run.folder.name + _about(d, swept, kin=k) for d, k in zip(runs, kin, strict=True)]


def _about(data: RunSeries, swept: list[str], *, kin: bool) -> str:
    mine = data.run.world.scenario
    values = flat_fields(mine)
    parts = ([f"{k}={json.dumps(values.get(k))}" for k in swept] if kin
             else [f"scenario {mine.name}"])  # fmt: skip
    parts += timeline(mine)
    ended = data.run.end_reason()
    parts += [] if ended == "completed" else [f"ended: {ended}"[:40]]
    return f" ({_short(parts)})" if parts else ""


def _short(parts: list[str], budget: int = 100) -> str:
    """Whole entries while they fit, then how many more (a value was cut mid-list)."""
    shown: list[str] = []
    for k, part in enumerate(parts):
        if len(", ".join([*shown, part])) > budget and shown:
            return ", ".join(shown) + f", and {len(parts) - k} more"
        shown.append(part)
    return ", ".join(shown)


def _tracks(runs: list[RunSeries], labels: list[str]) -> Figure:
    fig = Figure(figsize=(9, 9 + 0.18 * len(labels)), dpi=110, layout="constrained")
    ax = fig.subplots()
    seen: list[np.ndarray] = []
    drawn: list[tuple[str, np.ndarray]] = []  # (legend name, track)
    for k, (data, label) in enumerate(zip(runs, labels, strict=True)):
        xy = data.states.position[:, :, :2]
        for j, vid in enumerate(data.own):
            row = data.run.world.body(vid).row
            name, style = f"{label}: {vid}", _style(k, j)
            twin = same_track(xy[:, row], drawn)
            if twin is not None:  # dashed over the first, so both colours show
                name, style = f"{name} (the same track as {twin})", style | DASHED
            ax.plot(xy[:, row, 0], xy[:, row, 1], lw=1.8, label=name, **style)
            ax.plot(*xy[-1, row], "s", color=style["color"], ms=6, mec="black")
            drawn.append((f"{data.run.folder.name}: {vid}", xy[:, row]))
            seen.append(xy[:, row])
            draw_task(ax, data.run.world.scenario.vessels[row].task, _style(k, j)["color"], vid)
        seen.append(task_points(data.run.world, data.own))
    seen.append(_buoys(ax, runs))
    _square(ax, np.concatenate(seen))
    ax.set(xlabel="east x [m]", ylabel="north y [m]", aspect="equal",
           title="Trajectories of the scenario vessels (■ end; tasks dashed, dotted)")  # fmt: skip
    ax.grid(alpha=0.3)
    fig.legend(*_own_entries(ax), fontsize=7, loc="outside lower left")
    return fig


DASHED = {"ls": (0, (4, 4))}


def same_track(xy: np.ndarray, drawn: list[tuple[str, np.ndarray]]) -> str | None:
    """The name of the first track drawn that `xy` (T, 2) lies on within `SAME_M` at every
    sample: two runs a setting did not change had one line, the second hidden under it."""
    for name, other in drawn:
        if other.shape == xy.shape and np.allclose(other, xy, rtol=0.0, atol=SAME_M):
            return name
    return None


def _buoys(ax: Any, runs: list[RunSeries]) -> np.ndarray:
    """The scenarios' moored buoys, drawn once each: a run that stopped on one shows why."""
    moored = sorted({(b.x_m, b.y_m) for d in runs for b in d.run.world.scenario.buoys})
    xy = np.array(moored, dtype=np.float64).reshape(-1, 2)
    if len(xy):
        ax.scatter(xy[:, 0], xy[:, 1], s=30, c="#fac81e", edgecolors="black", lw=0.5,
                   label=f"buoys ({len(xy)})", zorder=3)  # fmt: skip
    return xy


def _own_entries(ax: Any) -> tuple[list[Any], list[str]]:
    """The tracks' legend entries, not every run's goal and route again."""
    pairs = [(h, t) for h, t in zip(*ax.get_legend_handles_labels(), strict=True)
             if not t.endswith((" goal", " route"))]  # fmt: skip
    return [h for h, _ in pairs], [t for _, t in pairs]


def _square(ax: Any, xy: np.ndarray) -> None:
    """A square view around the tracks: a near-straight one collapsed an equal-aspect plot to
    a strip."""
    lo, hi = np.nanmin(xy, axis=0), np.nanmax(xy, axis=0)
    centre, half = (lo + hi) / 2, max(float(np.max(hi - lo)) / 2, 1.0) * 1.1
    ax.set(xlim=(centre[0] - half, centre[0] + half), ylim=(centre[1] - half, centre[1] + half))


def _style(run: int, vessel: int) -> dict[str, Any]:
    """Run k's colour (the 10 dark ones of tab20 first, then the 10 light: its neighbours
    are a dark and a light blue), then the line style too; vessel j's line style."""
    color = COLORS((2 * run) % 20 + (run // 10) % 2)
    return {"color": color, "ls": STYLES[(vessel + run // 20) % len(STYLES)]}


def _speed_heading(runs: list[RunSeries], labels: list[str]) -> Figure:
    fig = Figure(figsize=(10, 6 + 0.18 * len(labels)), dpi=110, layout="constrained")
    speed, heading = fig.subplots(2, 1)
    for k, (data, label) in enumerate(zip(runs, labels, strict=True)):
        for j, vid in enumerate(data.own):
            style = _style(k, j)
            speed.plot(data.t, data.speed[vid], label=f"{label}: {vid}", **style)
            heading.plot(data.t, data.heading[vid], ".", ms=1.5, color=style["color"])
    speed_heading_axes(speed, heading)
    speed.get_legend().remove()
    fig.legend(fontsize=7, loc="outside lower left")
    return fig


def report(path: Path, runs: list[RunSeries], files: dict[str, str]) -> None:
    """`compare.html`: each run's vessels' figures in one table, then the figures."""
    rows = []
    for data, label in zip(runs, run_labels(runs), strict=True):
        vessels = (data.metrics or {}).get("vessels", {})
        ended = data.run.end_reason()
        rows += [_row(label, vid, vessels[vid], ended) for vid in data.own if vid in vessels]
    head = ("<tr><th>run</th><th>vessel</th><th>distance [m]</th><th>top speed [m/s]</th>"
            "<th>goal, nearest, contacts, thrust</th><th>ended</th></tr>")  # fmt: skip
    images = "".join(f'<img src="{f}" alt="{n}" style="max-width:100%">' for n, f in files.items())
    table = f"<table border=1>{head}{''.join(rows)}</table>"
    path.write_text("<!DOCTYPE html>\n<html><head><meta charset='utf-8'><title>CataBot runs "
                    f"compared</title></head><body>\n<h1>{len(runs)} runs compared</h1>"
                    f"{table}\n{images}\n</body></html>\n")  # fmt: skip


def _row(label: str, vid: str, m: dict[str, Any], ended: str) -> str:
    return table_row([label, vid, *vessel_cells(m), ended])
