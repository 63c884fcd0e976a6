"""A twist set-point beyond a vessel's thrusters is told once, with how far they reach."""

from __future__ import annotations

import logging
import math
from types import SimpleNamespace

import pytest

from catabot.bus.messages import ThrustCmd, TwistCmd
from catabot.config.scenario import ScriptStep
from catabot.config.vessel import load_vessel_model
from catabot.run.advice import advice_of
from services.physics.control import TwistController
from services.physics.reach import Reach


def _reach(*vessels: tuple[str, str, tuple[ScriptStep, ...]]) -> Reach:
    bodies = [SimpleNamespace(id=v, model=load_vessel_model(m), script=s) for v, m, s in vessels]
    controllers = [TwistController(b.model, dt_s=0.01) for b in bodies]
    return Reach(bodies, controllers)  # type: ignore[arg-type]


def _advice(caplog: pytest.LogCaptureFixture) -> list[str]:
    lines = [f"t physics.reach {r.levelname} {r.getMessage()}" for r in caplog.records]
    return [text for text in map(advice_of, lines) if text is not None]


def test_the_top_speed_told_is_the_damping_law_at_full_thrust(
    caplog: pytest.LogCaptureFixture,
) -> None:
    """The hull's damping and the windage's drag in still air (1/2 rho_a A_F C_x)."""
    model = load_vessel_model("wamv")
    thrust = sum(t.max_forward_n for t in model.thrusters)
    assert model.wind is not None
    lin, quad = model.damping.linear[0], model.damping.quadratic[0]
    quad += 0.5 * 1.225 * model.wind.frontal_area_m2 * model.wind.coefficients[0]
    top = (-lin + math.sqrt(lin * lin + 4 * quad * thrust)) / (2 * quad)  # lin u + quad u^2 = T
    reach = _reach(("ego", "wamv", ()))
    assert not reach.beyond("ego", top - 1e-3, 0.0) and reach.beyond("ego", top + 1e-3, 0.0)
    with caplog.at_level(logging.WARNING):
        reach.heard("ego", [TwistCmd(surge=2.0, yaw_rate=0.0)])
    (said,) = _advice(caplog)
    assert said.startswith("ego: the commanded twist 2 m/s at 0 rad/s is beyond its thrusters")
    assert f"about {top:.2f} m/s straight ahead" in said  # 1.52 m/s, the model file says


def test_told_once_a_vessel_and_never_for_a_set_point_in_reach(
    caplog: pytest.LogCaptureFixture,
) -> None:
    reach = _reach(("a", "catabot", ()), ("b", "catabot", ()))
    with caplog.at_level(logging.WARNING):
        reach.heard("a", [TwistCmd(surge=1.5, yaw_rate=0.0), ThrustCmd(thrust=(1.0, 1.0))])
        assert _advice(caplog) == []  # 1.5 m/s of its 1.87 straight ahead
        reach.heard("a", [TwistCmd(surge=1.0, yaw_rate=0.3)])  # the README's turn
        reach.heard("a", [TwistCmd(surge=3.0, yaw_rate=0.0)])
        reach.heard("b", [TwistCmd(surge=0.0, yaw_rate=-2.0)])
    said = _advice(caplog)
    assert [s.split(":")[0] for s in said] == ["a", "b"]
    assert "1.87 m/s straight ahead, 1.61 m/s astern, 0.27 rad/s turning in place" in said[0]


def test_a_scripted_twist_beyond_reach_is_told_at_the_start(
    caplog: pytest.LogCaptureFixture,
) -> None:
    steps = (
        ScriptStep(t_s=0.0, twist={"surge_mps": 1.0, "yaw_rate_radps": 0.0}),
        ScriptStep(t_s=5.0, twist={"surge_mps": 4.0, "yaw_rate_radps": 0.1}),
    )
    with caplog.at_level(logging.WARNING):
        _reach(("ego", "catabot", steps))
    (said,) = _advice(caplog)
    assert said.startswith("ego: the scripted twist 4 m/s at 0.1 rad/s is beyond")


def test_a_set_point_beyond_only_in_combination_says_so(caplog: pytest.LogCaptureFixture) -> None:
    """1.42 m/s and 0.18 rad/s are each within the catamaran's reach, not both at once: the
    advice read as a contradiction (examples/navigate.json's first order)."""
    reach = _reach(("c", "catabot", ()))
    with caplog.at_level(logging.WARNING):
        reach.heard("c", [TwistCmd(surge=1.42, yaw_rate=-0.18)])
    (said,) = _advice(caplog)
    assert "is beyond its thrusters together: a turn takes thrust from the speed (" in said


def test_a_turn_a_single_centreline_thruster_cannot_make_is_told(
    caplog: pytest.LogCaptureFixture,
) -> None:
    """One outboard on the centreline: a twist's yaw rate vanished in the allocation, the
    boat went straight, and nothing was said (the request was never scaled, only lost)."""
    model = load_vessel_model("catabot")
    one = model.thrusters[0].model_copy(update={"position_m": (-0.9, 0.0, -0.1)})
    body = SimpleNamespace(id="ego", model=model.model_copy(update={"thrusters": [one]}), script=())
    reach = Reach([body], [TwistController(body.model, dt_s=0.01)])  # type: ignore[list-item]
    assert not reach.beyond("ego", 0.5, 0.0) and reach.beyond("ego", 0.5, 0.1)
    with caplog.at_level(logging.WARNING):
        reach.heard("ego", [TwistCmd(surge=0.5, yaw_rate=0.1)])
    (said,) = _advice(caplog)
    assert "is beyond its thrusters" in said and "0.00 rad/s turning in place" in said
