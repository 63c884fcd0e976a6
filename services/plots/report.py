"""`report.html`: the run's summary and every figure on one page, beside the PNGs.

Only what the run folder holds and nothing of the wall clock (DESIGN.md §7), so one run
gives the same page every time it is plotted.
"""

from __future__ import annotations

import html
from pathlib import Path
from typing import Any

from catabot.config.differences import timeline
from catabot.run.metrics_summary import vessel_parts
from services.plots.series import RunSeries

STYLE = (
    "body{font-family:sans-serif;max-width:1200px;margin:2em auto;color:#222}"
    "table{border-collapse:collapse;margin:1em 0}td,th{border:1px solid #ccc;padding:4px 10px;"
    "text-align:left}img{max-width:100%;border:1px solid #ddd;margin:0.5em 0 1.5em}"
)


def _rows(pairs: list[tuple[str, Any]]) -> str:
    return "".join(
        f"<tr><th>{html.escape(k)}</th><td>{html.escape(str(v))}</td></tr>" for k, v in pairs
    )


def summary(data: RunSeries) -> list[tuple[str, Any]]:
    world = data.run.world
    s = world.scenario
    sensors = ", ".join(f"{m.vessel}.{m.config.name} ({m.config.type}, {m.config.rate_hz:g} Hz)"
                        for m in world.sensors) or "none"  # fmt: skip
    waves = s.water.waves.preset or f"Hs {s.water.waves.significant_height_m:g} m"
    ticks = len(data.t) - 1  # the rows hold the start state too
    return [
        ("scenario", s.name), ("seed", s.seed),
        ("simulated", f"{data.t[-1]:.2f} s recorded ({ticks} ticks of {s.dt_ns / 1e6:g} ms)"),
        ("ended", data.run.ended()),
        ("vessels", ", ".join(data.own)), ("traffic boats", len(world.boat_ids)),
        ("buoys", len(world.buoys)), ("sensors", sensors),
        ("rain", f"{s.rain.rate_mm_h:g} mm/h"), ("waves", waves),
        ("terrain", "none" if world.terrain is None else Path(world.terrain.name).name),
        ("settings timeline", "; ".join(timeline(s)) or "none"),
    ]  # fmt: skip


def vessel_cells(m: dict[str, Any]) -> list[str]:
    """A vessel's figures in metrics.json as table cells: distance, top speed, and the
    console summary's goal, nearest bodies, contacts and thrust (one run, or runs compared)."""
    return [f"{m['distance_m']:.1f}", f"{m['max_speed_mps']:.2f}",
            "; ".join(filter(None, vessel_parts(m)))]  # fmt: skip


def table_row(cells: list[str]) -> str:
    return "<tr>" + "".join(f"<td>{html.escape(c)}</td>" for c in cells) + "</tr>"


def _metrics(data: RunSeries) -> str:
    m = data.metrics or {}
    vessels = m.get("vessels", {})
    rows = "".join(table_row([v, *vessel_cells(vessels[v])]) for v in data.own if v in vessels)
    close = m.get("closest_approach")
    line = (
        f"<p>Closest approach: <b>{close['distance_m']:.2f} m</b> between "
        f"{html.escape(' and '.join(close['vessels']))} at {close['stamp_ns'] / 1e9:.2f} s</p>"
        if close else "<p>No closest approach (fewer than two vessels).</p>"
    )  # fmt: skip
    head = ("<tr><th>vessel</th><th>distance [m]</th><th>top speed [m/s]</th>"
            "<th>goal, nearest, contacts, thrust</th></tr>")  # fmt: skip
    return f"<table>{head}{rows}</table>{line}" if rows else line


def write(path: Path, data: RunSeries, figures: dict[str, str | None]) -> None:
    """`figures`: name -> PNG file name, or None when the run had nothing to draw."""
    title = f"CataBot run {data.run.folder.name}"
    parts = [f"<h1>{html.escape(title)}</h1>", f"<table>{_rows(summary(data))}</table>",
             "<h2>Navigation metrics</h2>", _metrics(data)]  # fmt: skip
    for name, file in figures.items():
        heading = name.replace("_", " ").capitalize()
        if file is None:
            parts.append(f"<h2>{heading}</h2><p>Nothing to plot in this run.</p>")
        else:
            parts.append(f'<h2>{heading}</h2><img src="{file}" alt="{name}">')
    body = "\n".join(parts)
    path.write_text(
        f"<!DOCTYPE html>\n<html><head><meta charset='utf-8'><title>{html.escape(title)}</title>"
        f"<style>{STYLE}</style></head><body>\n{body}\n</body></html>\n"
    )
