"""What the plots mark besides the tracks: contacts and groundings where and when they began
(services/plots/marks.py; a run whose summary counted collisions drew none of them), and a
compared track that lies on another (compare.py)."""

from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace
from typing import Any

import matplotlib.pyplot as plt
import numpy as np

from catabot.config.load import parse_scenario
from catabot.world.world import World
from services.plots import figures
from services.plots.compare import _tracks, same_track
from services.plots.marks import episodes, mark_places, mark_times

WORLD = World.resolve(parse_scenario({
    "name": "marks", "vessels": [{"id": "ego"}, {"id": "other", "pose": {"x_m": 10.0}}],
    "buoys": [{"id": "b1", "x_m": 20.0, "y_m": 0.0}],
}))  # fmt: skip
METRICS = {
    "collisions": [{"bodies": ["ego", "b1"], "start_s": 1.0, "end_s": 1.5},
                   {"bodies": ["ego", "other"], "start_s": 2.0, "end_s": None}],
    "groundings": [{"vessel": "other", "start_s": 0.5, "end_s": 3.0}],
    "traffic_collisions": [{"bodies": ["ego"], "start_s": "soon", "end_s": 1.0}],  # malformed
}  # fmt: skip


def _data(metrics: dict[str, Any]) -> Any:
    """Bodies moving along x: body i at x = 10 i + t."""
    t = np.arange(0.0, 3.01, 0.5)
    pos = np.zeros((len(t), 3, 3))
    pos[:, :, 0] = 10.0 * np.arange(3)[None, :] + t[:, None]
    return SimpleNamespace(run=SimpleNamespace(world=WORLD), states=SimpleNamespace(position=pos),
                           t=t, metrics=metrics)  # fmt: skip


def test_every_kind_is_read_and_a_malformed_entry_skipped() -> None:
    got = episodes(METRICS)
    assert [(e.kind, e.bodies, e.end_s) for e in got] == [
        ("collisions", ("ego", "b1"), 1.5),
        ("collisions", ("ego", "other"), None),  # still touching at the end
        ("groundings", ("other",), 3.0),
    ]
    assert episodes(None) == [] and episodes({"collisions": [{"bodies": ["ego"]}]}) == []


def test_each_episode_is_marked_where_it_began() -> None:
    fig, ax = plt.subplots()
    mark_places(ax, _data(METRICS))
    marks = {c.get_label(): c.get_offsets().tolist() for c in ax.collections}
    assert marks == {
        "collisions (2)": [[11.0, 0.0], [7.0, 0.0]],  # ego-b1 at 1 s: (1 + 21) / 2; ego-other
        "groundings (1)": [[10.5, 0.0]],
    }
    plt.close(fig)


def test_own_contacts_are_shaded_over_time_to_the_runs_end() -> None:
    fig, ax = plt.subplots()
    mark_times(ax, _data(METRICS))
    spans = [(p.get_x(), p.get_x() + p.get_width()) for p in ax.patches]  # type: ignore[attr-defined]
    assert spans == [(1.0, 1.5), (2.0, 3.0)]
    assert ax.get_legend() is not None
    plt.close(fig)
    fig, ax = plt.subplots()
    mark_times(ax, _data({}))
    assert not ax.patches and ax.get_legend() is None
    plt.close(fig)


def test_a_track_drawn_twice_is_named_as_the_first() -> None:
    """Two runs a setting did not change drew one line: the second hid under the first."""
    t = np.linspace(0.0, 1.0, 50)
    track = np.stack([10 * t, np.sin(t)], axis=1)
    drawn = [("a: ego", track), ("a: other", track + 5.0)]
    assert same_track(track + 0.004, drawn) == "a: ego"  # within 1 cm everywhere
    assert same_track(track + np.array([0.02, 0.0]), drawn) is None
    assert same_track(track[:-1], drawn) is None  # a shorter run is another track

    def run(name: str, shift: float) -> Any:
        pos = np.zeros((50, 1, 3))
        pos[:, 0, :2] = track + shift
        return SimpleNamespace(run=SimpleNamespace(world=World.resolve(parse_scenario(
            {"name": "c", "vessels": [{"id": "ego"}]})), folder=Path(name)),
            states=SimpleNamespace(position=pos), own=["ego"])  # fmt: skip

    fig = _tracks([run("a", 0.0), run("b", 0.0), run("c", 1.0)], ["a", "b (x=1)", "c"])
    names = [t.get_text() for t in fig.legends[0].get_texts()]
    assert names == ["a: ego", "b (x=1): ego (the same track as a: ego)", "c: ego"]


def test_the_minimum_marked_is_metrics_jsons_not_the_interpolated_curves() -> None:
    """The curve interpolates the traffic's 10 Hz rows: its minimum was 2 mm under the every-
    tick closest approach metrics.json has (4.42 against 4.43 m in an audit's run)."""
    close = {"distance_m": 4.4268, "vessels": ["ego", "other"], "stamp_ns": 9_630_000_000}
    data = _data({**METRICS, "closest_approach": close})
    data.closest, data.pairs, data.own = np.linspace(6.0, 4.42498, len(data.t)), {}, ["ego"]
    fig = figures.metrics(data)
    assert fig is not None
    labels = [line.get_label() for line in fig.axes[0].get_lines()]
    assert "minimum 4.43 m at 9.63 s" in labels
    plt.close(fig)
