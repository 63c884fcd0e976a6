"""Controller output for many vessels goes into the world at once (physics service path)."""

from __future__ import annotations

import numpy as np
import pytest

from catabot.bus.messages import ThrustCmd, TwistBatch, TwistCmd
from catabot.config.vessel import load_vessel_model
from services.physics.commands import CommandBook, Order
from services.physics.control import TwistController, TwistControllerBank
from services.physics.world import PhysicsWorld
from tests.services.physics.helpers import vessels


def _world() -> PhysicsWorld:
    cat, wamv = load_vessel_model("catabot"), load_vessel_model("wamv")
    return PhysicsWorld([("a", cat, (0, 0, 0, 0)), ("b", wamv, (20, 0, 0, 1))], dt_s=0.01)


def test_set_thrusts_equals_one_vessel_at_a_time() -> None:
    one, many = _world(), _world()
    commands = np.array([[0.4, -0.2, 0.9], [1.7, 0.3, 0.0]])  # padding column, a clamp
    one.set_thrust("a", commands[0, :2])
    one.set_thrust("b", np.clip(commands[1, :2], -1, 1))
    many.set_thrusts(np.array([0, 1]), commands)
    for world in (one, many):
        for _ in range(20):
            world.step()
    assert np.array_equal(one.state_arrays().position, many.state_arrays().position)


def test_set_thrusts_refuses_non_finite_and_unknown_rows() -> None:
    world = _world()
    with pytest.raises(ValueError, match="not finite"):
        world.set_thrusts(np.array([0]), np.array([[np.nan, 0.0]]))
    with pytest.raises(ValueError, match="for rows"):
        world.set_thrusts(np.array([5]), np.array([[0.0, 0.0]]))


def test_twist_batch_sets_each_boats_order_and_skips_bad_entries(
    caplog: pytest.LogCaptureFixture,
) -> None:
    boats = ("boat_000", "boat_001")
    book = CommandBook(vessels(*({"id": b} for b in boats)))
    batch = TwistBatch(3, 30, boats, np.array([1.0, np.nan]), np.array([0.1, 0.2]))
    book.take_batch(batch, boats)
    assert book.order("boat_000", 40) == Order(twist=(1.0, 0.1))
    assert book.order("boat_001", 40) == Order(thrust=(0.0, 0.0))  # refused: still at rest
    assert "non-finite for ['boat_001']" in caplog.text
    assert book.order("boat_000", 50) == Order(twist=(1.0, 0.1))  # held until the next


def test_orders_gathers_every_vessel_in_world_rows() -> None:
    """Script, lockstep set-point, external override: `orders` agrees with `order` vessel by
    vessel and hands the velocity-controlled rows over as arrays."""
    ego = {
        "id": "ego",
        "script": [
            {"t_s": 0.0, "thrust": [0.5, 0.5]},
            {"t_s": 1.0, "twist": {"surge_mps": 2.0, "yaw_rate_radps": 0.0}},
        ],
    }
    boats = ("boat_000", "boat_001", "boat_002")
    book = CommandBook(vessels(ego, *({"id": b} for b in boats)))
    book.take_batch(TwistBatch(0, 10, boats, np.array([1.0, 2.0, 3.0]), np.zeros(3)), boats)
    book.take("boat_001", [TwistCmd(0.5, 0.1, tick=-1)])
    book.take("boat_002", [ThrustCmd((0.1, -0.1))])
    thrust, rows, target = book.orders(0)
    assert thrust == {0: (0.5, 0.5), 3: (0.1, -0.1)}
    assert rows.tolist() == [1, 2] and target.tolist() == [[1.0, 0.0], [0.5, 0.1]]
    thrust, rows, target = book.orders(2_000_000_000)  # the script's twist step
    assert thrust == {3: (0.1, -0.1)} and rows.tolist() == [0, 1, 2]
    assert target[0].tolist() == [2.0, 0.0]
    for vid in ("ego", *boats):
        order = book.order(vid, 2_000_000_000)
        row = book.row[vid]
        assert order.thrust == thrust.get(row)
        assert order.twist == (tuple(target[rows.tolist().index(row)]) if row in rows else None)


def test_the_bank_matches_each_vessels_own_controller_as_the_controlled_set_changes() -> None:
    """The bank keeps its rows' constants between ticks: a different set of rows (a boat
    handed to a stack, one back) must give what each boat's own controller gives."""
    names = ["catabot", "wamv", "monohull"]
    models = [load_vessel_model(names[i % 3]) for i in range(9)]
    bank = TwistControllerBank(models, dt_s=0.01)
    own = [TwistController(m, dt_s=0.01) for m in models]
    rng = np.random.default_rng(5)
    for rows in ([0, 1, 2, 3, 4, 5, 6, 7, 8], [0, 1, 2, 3, 4, 5, 6, 7, 8], [1, 4, 7], [2, 8]):
        idx = np.array(rows)
        target, measured = rng.uniform(-1, 3, (idx.size, 2)), rng.uniform(-1, 2, (idx.size, 2))
        out = bank.command(idx, target, measured)
        for k, row in enumerate(rows):
            one = own[row].command(tuple(target[k]), tuple(measured[k]))
            assert np.allclose(out[k, : one.size], one, rtol=1e-12, atol=1e-12), (rows, row)
