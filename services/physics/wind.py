"""Wind loads on every vessel at once, from each model's windage (catabot.config.vessel.WindArea).

With the apparent wind (u_a, v_a) = wind velocity in the body frame minus the vessel's own
body-frame velocity (horizontal components only), per vessel:
    X = k_x u_a |u_a|,   Y = k_y v_a |v_a|,   N = -2 k_n u_a v_a
    k_x = 1/2 rho_a A_F C_x,  k_y = 1/2 rho_a A_L C_y,  k_n = 1/2 rho_a A_L L C_n
which is N = -1/2 rho_a A_L L C_n V_a^2 sin(2 gamma), gamma = atan2(v_a, u_a) (Fossen 2011
§10.1 with C_X ~ cos, C_Y ~ sin, C_N ~ sin 2 gamma, in VRX's component-wise form). The wrench
acts at the body origin; heel from the wind is neglected, as in VRX.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from catabot.config.vessel import VesselModel
from catabot.world.course import windage
from services.physics.hydro import Array


def wind_gains(models: Sequence[VesselModel], air_density: float) -> Array:
    """(N, 3) gains [k_x, k_y, k_n] per vessel (catabot/world/course.py's `windage`, which
    the top speed and the course-stability limit read too); zeros without windage."""
    return np.array([windage(m, air_density) for m in models], dtype=np.float64).reshape(-1, 3)


def wind_wrench(gains: Array, rot: Array, wind_world_xy: Array, nu: Array) -> Array:
    """Body-frame wind wrench (N, 6) [X, Y, 0, 0, 0, N].

    rot: body-to-world rotations (N, 3, 3); wind_world_xy: wind at each vessel (N, 2);
    nu: body-frame twist (N, 6), of which the linear velocity makes the apparent wind.
    """
    # Body components of a horizontal world vector w: R^T w = w_x R[0, :] + w_y R[1, :].
    wind_b = wind_world_xy[:, 0:1] * rot[:, 0, :2] + wind_world_xy[:, 1:2] * rot[:, 1, :2]
    apparent = wind_b - nu[:, :2]
    u_a, v_a = apparent[:, 0], apparent[:, 1]
    out = np.zeros((len(gains), 6))
    out[:, 0] = gains[:, 0] * u_a * np.abs(u_a)
    out[:, 1] = gains[:, 1] * v_a * np.abs(v_a)
    out[:, 5] = -2.0 * gains[:, 2] * u_a * v_a
    return out
