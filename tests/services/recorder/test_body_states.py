"""The recorder turns each `BodyStates` batch back into per-body `vessel/<id>/state` files."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from catabot.keys import Keys
from catabot.messages import BodyStates, Message, VesselState
from catabot.streams import BodyRows
from services.recorder.csv_sink import CsvSink
from services.recorder.service import per_body

KEYS = Keys("w")
IDS = ("ego", "buoy_0")
STATE_KEYS = [KEYS.vessel_state(i) for i in IDS]


def _batch(tick: int) -> BodyStates:
    n, t = len(IDS), tick * 0.1
    pos = np.array([[t, 2 * t, 0.01], [5.0, -1.0, 0.0]])
    quat = np.tile([0.0, 0.0, 0.1 * t, 1.0], (n, 1))
    vel = np.full((n, 3), 1 / 3)
    zero = np.zeros((n, 3))
    return BodyStates(tick, (tick + 1) * 100, IDS, pos, quat, vel, zero, zero, vel * 2)


def _by_hand(batch: BodyStates, i: int) -> VesselState:
    """The VesselState physics used to publish for row i (tuples of python floats)."""
    arrays = (batch.position, batch.orientation, batch.linear_velocity)
    arrays += (batch.angular_velocity, batch.linear_acceleration, batch.angular_acceleration)
    vec = [tuple(float(v) for v in a[i]) for a in arrays]
    return VesselState(batch.tick, batch.stamp_ns, *vec)


def _record(directory: Path, ticks: list[dict[str, list[Message]]]) -> None:
    with CsvSink(directory) as sink:
        for inputs in ticks:
            for key in sorted(inputs):
                for msg in inputs[key]:
                    sink.write(KEYS.relative(key), msg)
            sink.flush()


def test_batch_becomes_the_per_body_csv_rows(tmp_path: Path) -> None:
    batches = [_batch(k) for k in range(3)]
    rows = BodyRows(IDS)
    key, cmd = KEYS.world_states(), KEYS.cmd_twist("ego")
    expanded = [per_body({key: [b], cmd: []}, key, STATE_KEYS, rows) for b in batches]
    assert all(KEYS.world_states() not in e for e in expanded)
    assert expanded[1][KEYS.vessel_state("buoy_0")] == [_by_hand(batches[1], 1)]
    _record(tmp_path / "batch", expanded)
    by_hand = [{k: [_by_hand(b, i)] for i, k in enumerate(STATE_KEYS)} for b in batches]
    _record(tmp_path / "old", by_hand)
    for vid in IDS:
        name = f"vessel.{vid}.state.csv"
        text = (tmp_path / "batch" / name).read_text()
        assert text == (tmp_path / "old" / name).read_text()
        assert len(text.splitlines()) == 1 + len(batches)  # header + one row per tick
    assert sorted(p.name for p in (tmp_path / "batch").iterdir()) == [
        "vessel.buoy_0.state.csv",
        "vessel.ego.state.csv",
    ]


def test_inputs_without_a_batch_pass_through() -> None:
    inputs: dict[str, list[Message]] = {KEYS.cmd_twist("ego"): []}
    assert per_body(inputs, KEYS.world_states(), STATE_KEYS, BodyRows(IDS)) is inputs
