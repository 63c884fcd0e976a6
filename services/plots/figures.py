"""The figures of `catabot plot`, one function each, drawn with matplotlib's object API.

`Figure` objects with the Agg canvas, never pyplot: no global state, no display needed, and
a figure is garbage when its function returns. Each function returns None when the run has
nothing for it (no IMU, no thrust command), and the report says so.
"""

from __future__ import annotations

import json
from typing import Any

import numpy as np
from matplotlib.axes import Axes
from matplotlib.colors import LinearSegmentedColormap, TwoSlopeNorm
from matplotlib.figure import Figure
from matplotlib.patches import Circle
from numpy.typing import NDArray

from catabot.config.scenario import Scenario
from catabot.config.task import TaskConfig
from catabot.world.world import World
from services.plots.marks import boat_names, mark_places, mark_times
from services.plots.series import RunSeries

SEA = ["#0a1e5a", "#2870be", "#96d2e6"]
LAND = ["#468c46", "#96a050", "#8c6e46", "#c8c8c8"]
OWN_COLORS = ["#ff8c00", "#d62728", "#9467bd", "#8c564b", "#e377c2", "#17becf"]
MARGIN_M = 40.0


def _figure(rows: int = 1, cols: int = 1, *, size: tuple[float, float] = (10, 4)) -> Figure:
    fig = Figure(figsize=size, dpi=110, layout="constrained")
    fig.subplots(rows, cols, squeeze=False)
    return fig


def _axes(fig: Figure) -> list[Axes]:
    return list(fig.axes)


def _color(k: int) -> str:
    return OWN_COLORS[k % len(OWN_COLORS)]


def trajectories(data: RunSeries) -> Figure:
    """Every vessel's track over the terrain (cropped to the tracks, the tasks and the
    scenario's buoys: the traffic's waypoint buoys may lie far off), buoys, starts and ends."""
    return _trajectories(data, *_view(data, everyone=True), "Trajectories")


def trajectories_own(data: RunSeries) -> Figure | None:
    """The scenario's own vessels close up, when the traffic spreads the full view over more
    than four times their area (a fleet of three filled a corner of a 300 m frame)."""
    lo, hi = _view(data, everyone=True)
    own_lo, own_hi = _view(data, everyone=False)
    if not data.run.world.boat_ids or 4 * np.prod(own_hi - own_lo) > np.prod(hi - lo):
        return None
    return _trajectories(data, own_lo, own_hi, "Own vessels' trajectories")


def _view(data: RunSeries, *, everyone: bool) -> tuple[np.ndarray, np.ndarray]:
    """The corners of a view holding the tracks (every vessel's, or the scenario's own) and
    the tasks, and for every vessel's the scenario's buoys, with a margin."""
    world, xy = data.run.world, data.states.position[:, :, :2]
    rows = len(world.vessels) if everyone else len(world.scenario.vessels)
    moored = [(b.x_m, b.y_m) for b in world.scenario.buoys] if everyone else []
    seen = np.concatenate([xy[:, :rows].reshape(-1, 2), task_points(world, data.own),
                           np.array(moored, dtype=np.float64).reshape(-1, 2)])  # fmt: skip
    margin = MARGIN_M if everyone else MARGIN_M / 4
    return np.nanmin(seen, axis=0) - margin, np.nanmax(seen, axis=0) + margin


def _trajectories(data: RunSeries, lo: np.ndarray, hi: np.ndarray, title: str) -> Figure:
    world, pos = data.run.world, data.states.position
    vessels = len(world.vessels)
    xy = pos[:, :, :2]
    fig = _figure(size=(8.5, 8))
    ax = _axes(fig)[0]
    _terrain(ax, data, lo, hi)
    own = {world.body(v).row for v in data.own}
    first = len(world.scenario.vessels)
    for row in range(first, vessels):
        ax.plot(xy[:, row, 0], xy[:, row, 1], color="white", lw=0.8, alpha=0.8)
    if vessels > first:  # where each boat ended: one holding station has no track to see
        ax.scatter(xy[-1, first:vessels, 0], xy[-1, first:vessels, 1], s=14, c="white",
                   marker="s", edgecolors="black", lw=0.4, zorder=3)  # fmt: skip
    if vessels > len(own):
        ax.plot([], [], color="white", lw=0.8, label=f"traffic ({vessels - len(own)} boats)")
    boat_names(ax, world, xy)
    for k, vid in enumerate(data.own):
        row = world.body(vid).row
        ax.plot(xy[:, row, 0], xy[:, row, 1], color=_color(k), lw=2.2, label=vid)
        ax.plot(*xy[0, row], "o", color=_color(k), ms=7, mec="black")
        ax.plot(*xy[-1, row], "s", color=_color(k), ms=7, mec="black")
        draw_task(ax, world.scenario.vessels[row].task, _color(k), vid)
    mark_places(ax, data)
    if world.buoys:
        b = xy[-1, vessels:]
        ax.scatter(b[:, 0], b[:, 1], s=14, c="#fac81e", edgecolors="black", lw=0.4,
                   label=f"buoys ({len(b)})", zorder=3)  # fmt: skip
    ax.set(xlim=(lo[0], hi[0]), ylim=(lo[1], hi[1]), xlabel="east x [m]", ylabel="north y [m]",
           title=f"{title}, {data.t[-1]:.1f} s (o start, ■ end)", aspect="equal")  # fmt: skip
    ax.legend(loc="best", fontsize=8, framealpha=0.9, facecolor="#9fb0c0")  # white shows
    return fig


def task_points(world: World, own: Any) -> np.ndarray:
    """The goals (their whole circles) and route points of the vessels drawn, (K, 2): the
    view must hold them."""
    points: list[tuple[float, float]] = []
    for vid in own:
        task = world.scenario.vessels[world.body(vid).row].task
        if task is not None and task.goal is not None:
            g = task.goal
            points += [
                (g.x_m - g.radius_m, g.y_m - g.radius_m),
                (g.x_m + g.radius_m, g.y_m + g.radius_m),
            ]
        if task is not None and task.route is not None:
            points += [(float(x), float(y)) for x, y in task.route]
    return np.array(points, dtype=np.float64).reshape(-1, 2)


def draw_task(ax: Axes, task: TaskConfig | None, color: str, vid: str) -> None:
    """A vessel's goal region (dashed circle) and route (dotted line), as metrics.json
    measures them."""
    if task is None:
        return
    if task.goal is not None:
        goal = task.goal
        ax.add_patch(Circle((goal.x_m, goal.y_m), goal.radius_m, fill=False, ls="--", lw=1.4,
                            ec=color, label=f"{vid} goal"))  # fmt: skip
    if task.route is not None:
        route = np.asarray(task.route, dtype=np.float64)
        ax.plot(route[:, 0], route[:, 1], ":", color=color, lw=1.4, marker=".",
                label=f"{vid} route")  # fmt: skip


def _terrain(ax: Axes, data: RunSeries, lo: Any, hi: Any) -> None:
    terrain = data.run.world.terrain
    if terrain is None:
        ax.set_facecolor(SEA[1])
        return
    z = terrain.elevation_m
    w, h = terrain.size_m
    norm = TwoSlopeNorm(vcenter=0.0, vmin=min(float(z.min()), -1.0), vmax=max(float(z.max()), 1.0))
    cmap = LinearSegmentedColormap.from_list(
        "sea_land", [(0.0, SEA[0]), (0.25, SEA[1]), (0.4999, SEA[2]), (0.5, LAND[0]),
                     (0.7, LAND[1]), (0.85, LAND[2]), (1.0, LAND[3])])  # fmt: skip
    image = ax.imshow(z, origin="lower", extent=(0, w, 0, h), cmap=cmap, norm=norm)
    ax.contour(np.linspace(0, w, z.shape[1]), np.linspace(0, h, z.shape[0]), z, levels=[0.0],
               colors="black", linewidths=0.6)  # fmt: skip
    ax.figure.colorbar(image, ax=ax, shrink=0.7, label="elevation [m]")


def speed_heading(data: RunSeries) -> Figure | None:
    if not data.own:
        return None
    fig = _figure(2, 1, size=(10, 6))
    speed, heading = _axes(fig)
    for k, vid in enumerate(data.own):
        speed.plot(data.t, data.speed[vid], color=_color(k), label=vid)
        heading.plot(data.t, data.heading[vid], ".", ms=2, color=_color(k), label=vid)
    speed_heading_axes(speed, heading)
    heading.legend(fontsize=8)
    _changes(speed, data.run.world.scenario)
    _changes(heading, data.run.world.scenario, labelled=False)
    return fig


def speed_heading_axes(speed: Axes, heading: Axes) -> None:
    """The speed and heading panels' labels (one run's, or runs compared)."""
    speed.set(ylabel="speed over ground [m/s]", title="Speed and heading")
    heading.set(ylabel="heading [deg from north, clockwise]", xlabel="simulated time [s]",
                ylim=(0, 360), yticks=range(0, 361, 90))  # fmt: skip
    for ax in (speed, heading):
        ax.grid(alpha=0.3)
    speed.legend(fontsize=8)


def _changes(ax: Axes, scenario: Scenario, *, labelled: bool = True) -> None:
    """Each setting change of the run (its `settings` timeline, `catabot set` included) as a
    dotted line, named on top: why a track bends when the current was set mid-run."""
    for change in scenario.settings:
        ax.axvline(change.t_s, ls=":", lw=1.0, color="dimgray")
        if labelled:
            text = f"{change.key} = {json.dumps(change.value)}"[:40]
            ax.annotate(text, (change.t_s, 0.97), xycoords=("data", "axes fraction"),
                        xytext=(2, 0), textcoords="offset points", fontsize=7, va="top",
                        color="dimgray", rotation=90)  # fmt: skip


def thrust(data: RunSeries) -> Figure | None:
    owners = [v for v in data.own if v in data.thrust or v in data.setpoint]
    if not owners:
        return None
    fig = _figure(len(owners), 1, size=(10, 2.8 * len(owners)))
    end = float(data.t[-1])
    for ax, vid in zip(_axes(fig), owners, strict=True):
        kinds = (data.thrust.get(vid), data.setpoint.get(vid))
        for series, other, style in ((*kinds, "-"), (*kinds[::-1], "--")):
            if series is None:
                continue
            t, held = _in_force(series.t, series.values, other.t if other else None, end)
            for c, name in enumerate(series.names):  # thinner each: equal ones both show
                ax.step(t, held[:, c], style, where="post", label=name, lw=max(2.8 - c, 1.0))
        ax.set(title=f"{vid}: commands (solid: thrust, -1..1; dashed: twist set-points)",
               xlabel="simulated time [s]", xlim=(0, end),
               ylabel="thrust [-1..1]; set-point [m/s, rad/s]")  # fmt: skip
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8, loc="best")
    return fig


def _in_force(
    t: np.ndarray, values: np.ndarray, other: np.ndarray | None, end: float
) -> tuple[np.ndarray, np.ndarray]:
    """Each command held until the next, or until the other kind's next (NaN: a thrust
    stops ruling when a twist comes, and back), the last to the run's end. The thrust plot
    drew the last thrust on for 20 s while the twist controller drove."""
    cut = np.asarray(other if other is not None else [], dtype=np.float64)
    times = np.concatenate([t, cut])
    rows = np.concatenate([values, np.full((cut.size, values.shape[1]), np.nan)])
    order = np.argsort(times, kind="stable")
    return np.append(times[order], end), np.vstack([rows[order], rows[order][-1:]])


def imu(data: RunSeries) -> Figure | None:
    if not data.imu:
        return None
    fig = _figure(len(data.imu), 2, size=(11, 3.2 * len(data.imu)))
    axes = _axes(fig)
    for k, (owner, s) in enumerate(data.imu.items()):
        acc, gyro = axes[2 * k], axes[2 * k + 1]
        for c, axis in enumerate("xyz"):
            acc.plot(s.t, s.values[:, c], lw=0.7, label=axis)
            gyro.plot(s.t, s.values[:, 3 + c], lw=0.7, label=axis)
        acc.set(title=f"{owner}: specific force", ylabel="[m/s²]", xlabel="simulated time [s]")
        gyro.set(title=f"{owner}: angular rate", ylabel="[rad/s]", xlabel="simulated time [s]")
        for ax in (acc, gyro):
            ax.grid(alpha=0.3)
            ax.legend(fontsize=8, ncol=3)
    return fig


def rain_steps(scenario: Scenario, t_end: float) -> tuple[NDArray[np.float64], ...]:
    """The rain rate over the run as steps (times, rates): the scenario's, then every
    change of its `settings` timeline (a run folder's holds the live ones `catabot set` made)."""
    points = [(0.0, scenario.rain.rate_mm_h)]
    changes = [(c.t_s, c.value) for c in scenario.settings if c.key == "rain"]
    points += sorted((t, float(v)) for t, v in changes if isinstance(v, int | float))
    points.append((max(t_end, points[-1][0]), points[-1][1]))
    return np.array([t for t, _ in points]), np.array([r for _, r in points])


def lidar_rain(data: RunSeries) -> Figure | None:
    """Returns and rain returns per scan over time beside the rain rate, and the rain share."""
    if not data.lidar:
        return None
    t_end = max(float(s.t[-1]) for s in data.lidar.values())
    steps_t, steps_rate = rain_steps(data.run.world.scenario, t_end)
    fig = _figure(1, 2, size=(11, 4))
    counts, share = _axes(fig)
    for k, (owner, s) in enumerate(data.lidar.items()):
        counts.plot(s.t, s.values[:, 0], color=_color(k), label=f"{owner}: returns")
        counts.plot(s.t, s.values[:, 1], "--", color=_color(k), label=f"{owner}: rain returns")
        fraction = s.values[:, 1] / np.maximum(s.values[:, 0], 1)
        rate = steps_rate[np.searchsorted(steps_t, s.t, side="right") - 1]  # at each scan
        share.plot(rate, 100 * fraction, "o", alpha=0.5, color=_color(k),
                   label=f"{owner} ({len(s.t)} scans)")  # fmt: skip
    counts.set(title="LiDAR returns per scan", xlabel="simulated time [s]", ylabel="points")
    counts.set_ylim(0, counts.get_ylim()[1] * 1.3)  # room for the legend above the lines
    rain = counts.twinx()
    rain.step(steps_t, steps_rate, where="post", color="magenta", lw=1.2, label="rain rate [mm/h]")
    rain.set(ylabel="rain rate [mm/h]", ylim=(0, max(50.0, float(steps_rate.max()) * 1.1)))
    lines = counts.get_legend_handles_labels()
    more = rain.get_legend_handles_labels()
    counts.legend(lines[0] + more[0], lines[1] + more[1], fontsize=8, loc="upper right", ncol=2)
    share.set(title="Rain returns against rain rate", xlabel="rain rate [mm/h]",
              ylabel="rain returns [% of returns]", xlim=(-2, 52))  # fmt: skip
    share.set_ylim(0, max(1.0, share.get_ylim()[1] * 1.2))
    share.legend(fontsize=8, loc="upper left")
    if not steps_rate.any():  # every scan sits at (0, 0) on the frame's edge: said
        share.text(0.5, 0.5, "no rain in this run\n(every scan at 0 mm/h)", ha="center",
                   va="center", transform=share.transAxes, color="0.4")  # fmt: skip
    for ax in (counts, share):
        ax.grid(alpha=0.3)
    return fig


def metrics(data: RunSeries) -> Figure | None:
    """Closest approach of a scenario vessel to any other over time (metrics.json's); distance
    and top speed by vessel."""
    fig = _figure(1, 2, size=(11, 4))
    gap, bars = _axes(fig)
    finite = np.isfinite(data.closest)
    if finite.any():
        gap.plot(data.t, data.closest, color="#1f77b4", label="own vessel to any other")
        k = int(np.nanargmin(np.where(finite, data.closest, np.nan)))
        close = (data.metrics or {}).get("closest_approach")  # every tick's, not interpolated
        d, t = (
            (close["distance_m"], close["stamp_ns"] / 1e9)
            if close
            else (data.closest[k], data.t[k])
        )
        gap.plot(t, d, "v", color="red", label=f"minimum {d:.2f} m at {t:.2f} s")
        for k, (pair, apart) in enumerate(data.pairs.items()):
            gap.plot(data.t, apart, lw=0.9, ls="--", color=_color(k), label=pair)
        gap.legend(fontsize=8)
    else:  # one vessel alone: an empty 0..1 panel read as a plot gone wrong
        gap.text(0.5, 0.5, "one vessel: no pair to measure", ha="center", va="center",
                 transform=gap.transAxes, color="gray")  # fmt: skip
    mark_times(gap, data)
    gap.set(title="Closest approach to another vessel (dashed: own pairs)",
            xlabel="simulated time [s]", ylabel="distance [m]")  # fmt: skip
    gap.grid(alpha=0.3)
    vessels = (data.metrics or {}).get("vessels", {})
    shown = [v for v in data.own if v in vessels]
    if not shown:
        return fig
    x = np.arange(len(shown))
    dist = [vessels[v]["distance_m"] for v in shown]
    top = [vessels[v]["max_speed_mps"] for v in shown]
    bars.bar(x - 0.2, dist, 0.4, color="#ff8c00", label="distance [m]")
    speed = bars.twinx()
    speed.bar(x + 0.2, top, 0.4, color="#2ca02c", label="top speed [m/s]")
    bars.set(xticks=x, xticklabels=shown, ylabel="distance travelled [m]", ylim=(0, max(
        max(dist) * 1.3, 1.0)), title="Navigation metrics (metrics.json)")  # fmt: skip
    speed.set(ylabel="top speed [m/s]", ylim=(0, max(max(top) * 1.3, 0.1)))  # 1e-16: at rest
    handles = [bars.get_legend_handles_labels()[0][0], speed.get_legend_handles_labels()[0][0]]
    bars.legend(handles, ["distance [m]", "top speed [m/s]"], loc="upper center", ncol=2,
                fontsize=8)  # fmt: skip
    return fig


FIGURES = {
    "trajectories": trajectories,
    "trajectories_own": trajectories_own,
    "speed_heading": speed_heading,
    "thrust": thrust,
    "imu": imu,
    "lidar_rain": lidar_rain,
    "metrics": metrics,
}
