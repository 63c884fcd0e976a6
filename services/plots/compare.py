"""`catabot plot RUN RUN ...`: several runs' scenario vessels on one set of axes.

Why: a lab compares a controller in calm water with the same in a current, a sweep a gain's
values; one run's plots each, side by side, do not show the difference. The runs are told
apart by colour (named by their folders, and by the settings that differ between them), each
vessel of a run by its line style; `compare.html` has every run's figures in one table.
"""

from __future__ import annotations

import html
from pathlib import Path
from typing import Any

from matplotlib.figure import Figure

from catabot.run.metrics_summary import vessel_parts
from services.plots.figures import speed_heading_axes
from services.plots.series import RunSeries

STYLES = ["-", "--", ":", "-."]
COLORS = ["#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2"]


def figures(runs: list[RunSeries]) -> dict[str, Figure]:
    labels = run_labels(runs)
    return {"compare_trajectories": _tracks(runs, labels),
            "compare_speed_heading": _speed_heading(runs, labels)}  # fmt: skip


def run_labels(runs: list[RunSeries]) -> list[str]:
    """Each run's folder name, and the scenario fields in which it differs from the first."""
    first = _flat(runs[0].run.world.scenario.model_dump(mode="json"))
    labels = []
    for data in runs:
        mine = _flat(data.run.world.scenario.model_dump(mode="json"))
        differ = [f"{k}={mine[k]}" for k in sorted(mine) if k != "name" and mine[k] != first.get(k)]
        labels.append(data.run.folder.name + (f" ({', '.join(differ)[:90]})" if differ else ""))
    return labels


def _flat(tree: Any, prefix: str = "") -> dict[str, Any]:
    """A nested scenario as `a.b.0.c: value` leaves (a list of plain values is one value: a
    current's [east, north])."""
    if isinstance(tree, list) and any(isinstance(v, dict | list) for v in tree):
        tree = dict(enumerate(tree))
    if not isinstance(tree, dict):
        return {prefix: tree}
    out: dict[str, Any] = {}
    for key, value in tree.items():
        out |= _flat(value, f"{prefix}.{key}" if prefix else str(key))
    return out


def _tracks(runs: list[RunSeries], labels: list[str]) -> Figure:
    fig = Figure(figsize=(9, 8), dpi=110, layout="constrained")
    ax = fig.subplots()
    for k, (data, label) in enumerate(zip(runs, labels, strict=True)):
        xy = data.states.position[:, :, :2]
        for j, vid in enumerate(data.own):
            row = data.run.world.body(vid).row
            ax.plot(xy[:, row, 0], xy[:, row, 1], STYLES[j % len(STYLES)], lw=1.8,
                    color=COLORS[k % len(COLORS)], label=f"{label}: {vid}")  # fmt: skip
            ax.plot(*xy[-1, row], "s", color=COLORS[k % len(COLORS)], ms=6, mec="black")
    ax.set(xlabel="east x [m]", ylabel="north y [m]", aspect="equal",
           title="Trajectories of the scenario vessels (■ end)")  # fmt: skip
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, loc="best")
    return fig


def _speed_heading(runs: list[RunSeries], labels: list[str]) -> Figure:
    fig = Figure(figsize=(10, 6), dpi=110, layout="constrained")
    speed, heading = fig.subplots(2, 1)
    for k, (data, label) in enumerate(zip(runs, labels, strict=True)):
        for j, vid in enumerate(data.own):
            style = dict(color=COLORS[k % len(COLORS)], label=f"{label}: {vid}")
            speed.plot(data.t, data.speed[vid], STYLES[j % len(STYLES)], **style)
            heading.plot(data.t, data.heading[vid], ".", ms=1.5, **style)
    speed_heading_axes(speed, heading)
    return fig


def report(path: Path, runs: list[RunSeries], files: dict[str, str]) -> None:
    """`compare.html`: each run's vessels' figures in one table, then the figures."""
    rows = []
    for data, label in zip(runs, run_labels(runs), strict=True):
        vessels = (data.metrics or {}).get("vessels", {})
        rows += [_row(label, vid, vessels[vid]) for vid in data.own if vid in vessels]
    head = ("<tr><th>run</th><th>vessel</th><th>distance [m]</th><th>top speed [m/s]</th>"
            "<th>goal, nearest, contacts, thrust</th></tr>")  # fmt: skip
    images = "".join(f'<img src="{f}" alt="{n}" style="max-width:100%">' for n, f in files.items())
    table = f"<table border=1>{head}{''.join(rows)}</table>"
    path.write_text("<!DOCTYPE html>\n<html><head><meta charset='utf-8'><title>CataBot runs "
                    f"compared</title></head><body>\n<h1>{len(runs)} runs compared</h1>"
                    f"{table}\n{images}\n</body></html>\n")  # fmt: skip


def _row(label: str, vid: str, m: dict[str, Any]) -> str:
    parts = html.escape("; ".join(filter(None, vessel_parts(m))))
    cells = [html.escape(label), html.escape(vid), f"{m['distance_m']:.1f}",
             f"{m['max_speed_mps']:.2f}", parts]  # fmt: skip
    return "<tr>" + "".join(f"<td>{c}</td>" for c in cells) + "</tr>"
