"""The longest physics step at which a vessel model stays stable: its forces are explicit.

Why: DART steps the hydrodynamic forces as they were at the start of the step (semi-implicit
Euler: v += dt F(x, v) / M, then x += dt v), so a stiff or strongly damped degree of freedom
diverges when the step is too long. An audit's WAM-V at dt 0.1 s, which the schema allows,
rolled itself apart in 1.8 s (its roll period is 0.37 s), and a 0.3 kg model on the
catamaran's hulls was thrown 17 m up on its first step (heave damping 440 N s/m on 0.3 kg).
Per degree of freedom, with stiffness k, linear damping c and mass or inertia M (its added
mass included), a = k dt^2 / M and b = c dt / M, the step's amplification matrix has its
eigenvalues inside the unit circle while b < 2 and a + 2 b < 4 (Jury's conditions). The
quadratic damping and the couplings between the degrees of freedom are left out, so a step
is refused beyond MARGIN of that limit: the WAM-V's limit is then 0.087 s, where it ran at
0.08 s from a 3 degree heel and diverged at 0.1 s.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from catabot.config.base import ScenarioError
from catabot.config.scenario import Scenario
from catabot.config.vessel import VesselModel
from catabot.config.waves import GRAVITY
from catabot.world.placement import Models, model_fields
from catabot.world.stability import hydrostatics

MARGIN = 0.8  # of the linear limit: room for the quadratic damping and the couplings
CELLS = (6, 12, 48)  # hydrostatics' cells per hull: enough here, and 15 times cheaper
DOFS = ("surge", "sway", "heave", "roll", "pitch", "yaw")


@dataclass(frozen=True)
class StepLimit:
    """The longest stable step (s, MARGIN applied), the degree of freedom that sets it and
    that one's undamped natural period (s; inf: no restoring force)."""

    dt_s: float
    dof: str
    period_s: float


def step_limit(model: VesselModel, density: float) -> StepLimit:
    """The model's longest stable physics step, floating upright in water of `density`."""
    return min((_limit(dof, k, c, m) for dof, k, c, m in _dofs(model, density)),
               key=lambda s: s.dt_s)  # fmt: skip


def check_step(scenario: Scenario, models: Models) -> None:
    """ScenarioError naming the first model the scenario's step `dt_ns` is too long for."""
    dt, density = scenario.dt_ns * 1e-9, scenario.water.density_kg_m3
    checked: set[str] = set()  # a model several fields name (traffic models, boats): once
    for where, ref in model_fields(scenario):
        if ref is None or ref in checked or not _in_run(where, scenario):
            continue
        checked.add(ref)
        if models[ref].sinks_in(density):
            continue  # its own refusal (world.py) names it
        limit = step_limit(models[ref], density)
        if dt > limit.dt_s:
            raise ScenarioError(_too_long(where, ref, dt, limit))


def _in_run(where: str, scenario: Scenario) -> bool:
    """Whether the model the field names has a body in the run: traffic models only with
    traffic, the buoy's only with buoys (given, or laid on the traffic's waypoints)."""
    traffic = scenario.traffic.count > 0
    if where == "buoys":
        return bool(scenario.buoys) or (traffic and scenario.traffic.waypoints.buoys)
    return traffic or not where.startswith("traffic.")


def _too_long(where: str, ref: str, dt: float, limit: StepLimit) -> str:
    period = f"natural period {limit.period_s:.3g} s, " if math.isfinite(limit.period_s) else ""
    return (f"{where}: model {ref!r} is stable only with a physics step up to "
            f"{limit.dt_s:.3g} s ({limit.dof}: {period}its forces are explicit); dt_ns "
            f"{round(dt * 1e9)} ({dt:g} s) is longer: shorten dt_ns, or give the model "
            "more mass, inertia or added mass against its stiffness and damping")  # fmt: skip


def _dofs(model: VesselModel, density: float) -> list[tuple[str, float, float, float]]:
    """(name, stiffness, linear damping, mass or inertia with added mass) per degree of
    freedom; heave, roll and pitch have the hydrostatic stiffness."""
    h = hydrostatics(model, density, cells=CELLS)
    weight = model.mass_kg * GRAVITY
    stiffness = (0.0, 0.0, density * GRAVITY * h.waterplane_m2, weight * h.gm_roll_m,
                 weight * h.gm_pitch_m, 0.0)  # fmt: skip
    inertia = (model.mass_kg,) * 3 + tuple(model.inertia_kgm2)
    mass = [i + a for i, a in zip(inertia, model.added_mass, strict=True)]
    damping = model.damping.linear
    return [(DOFS[i], stiffness[i], damping[i], mass[i]) for i in range(6)]


def _limit(dof: str, k: float, c: float, m: float) -> StepLimit:
    """b < 2 and a + 2 b < 4, solved for dt: k dt^2 / m + 2 c dt / m = 4."""
    w2, beta = max(k, 0.0) / m, c / m  # a negative stiffness capsizes: another note's
    damped = 2.0 / beta if beta > 0 else math.inf
    stiff = (math.sqrt(beta * beta + 4.0 * w2) - beta) / w2 if w2 > 0 else math.inf
    period = 2 * math.pi / math.sqrt(w2) if w2 > 0 else math.inf
    return StepLimit(MARGIN * min(damped, stiff), dof, period)
