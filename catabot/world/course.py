"""Whether a vessel model keeps a straight course: the linear sway-yaw stability criterion.

Why here: a model file whose added mass brings a Munk moment larger than its damping can
hold circles on equal thrust; the bundled catamaran did at full thrust. `scenario validate
MODEL.json` says so, and the tests hold every bundled model to it, by this one rule.

Straight at surge u > 0, the linearised sway and yaw (Fossen 2011, §7.1, no rudder) are
    (m + A22) v' = -(Y_v - Y_uv u) v - (m + A11) u r
    (I + A66) r' = -N_r r + (A11 - A22 + N_uv) u v
(the Munk moment -(A22 - A11) u v and the hull's lift Y_uv |u| v, N_uv u v; the COG on the
centreline at the origin), stable while (Y_v - Y_uv u) N_r > (m + A11) (A22 - A11 - N_uv) u^2.
In still air the windage's yaw moment -2 k_n u v (services/physics/wind.py, k_n = 1/2 rho_a
A_L L C_n) adds to the Munk moment: A22 - A11 - N_uv + 2 k_n (an audit found it left out:
the monohull's limit 7.2 m/s, not 7.9).
"""

from __future__ import annotations

import math

from catabot.config.environment import WindConfig
from catabot.config.vessel import VesselModel

STILL_AIR = WindConfig().air_density_kg_m3  # the scenario's default air


def windage(model: VesselModel, air_density: float) -> tuple[float, float, float]:
    """The wind law's gains [k_x, k_y, k_n] (services/physics/wind.py): 1/2 rho_a A_F C_x,
    1/2 rho_a A_L C_y and 1/2 rho_a A_L L C_n; zeros for a model without windage."""
    w = model.wind
    if w is None:
        return 0.0, 0.0, 0.0
    c_x, c_y, c_n = w.coefficients
    half_rho = 0.5 * air_density
    return (half_rho * w.frontal_area_m2 * c_x, half_rho * w.lateral_area_m2 * c_y,
            half_rho * w.lateral_area_m2 * w.length_m * c_n)  # fmt: skip


def surge_drag(model: VesselModel, *, air_density: float = STILL_AIR) -> tuple[float, float]:
    """The linear and quadratic surge drag (N per m/s, per (m/s)^2) in still air: the hull's
    damping, and its windage's 1/2 rho_a A_F C_x u^2 in the apparent wind (a model with wind
    areas, services/physics/wind.py). The top speed and the velocity controller's
    feed-forward both hold a speed against it."""
    return model.damping.linear[0], model.damping.quadratic[0] + windage(model, air_density)[0]


def top_speed_mps(model: VesselModel, *, air_density: float = STILL_AIR) -> float:
    """The steady surge speed at full forward thrust along the body x axis (0: none), in
    still air (`surge_drag`)."""
    push = sum(t.max_forward_n * math.cos(t.yaw_rad) for t in model.thrusters)
    linear, quadratic = surge_drag(model, air_density=air_density)
    if push <= 0.0:
        return 0.0
    if quadratic <= 0.0:
        return push / linear if linear > 0 else math.inf
    return (-linear + math.sqrt(linear * linear + 4.0 * quadratic * push)) / (2.0 * quadratic)


def unstable_above_mps(model: VesselModel, *, air_density: float = STILL_AIR) -> float:
    """The surge speed above which a straight course is unstable (inf: at no speed): the
    positive root of a u^2 + Y_uv N_r u - Y_v N_r = 0, in still air."""
    lift_y, lift_n = model.damping.lift_uv
    munk = model.added_mass[1] - model.added_mass[0] - lift_n + 2.0 * windage(model, air_density)[2]
    a = (model.mass_kg + model.added_mass[0]) * munk
    if a <= 0.0:
        return math.inf
    n_r = model.damping.linear[5]
    b, c = lift_y * n_r, max(model.damping.linear[1] * n_r, 0.0)
    return (-b + math.sqrt(b * b + 4.0 * a * c)) / (2.0 * a)
