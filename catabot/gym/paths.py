"""Where the other scenario vessels go during an episode, so that no start is drawn on a path.

Why: the harbour's scripted WAM-V circles 20 m around (299, 319), through the ego's home; a
StationKeep ego that held still there was rammed after about 40 s whatever it learned. A twist
script is tracked closely by physics' twist controller, through the water: its path is arcs
(constant surge and yaw rate per step) carried by the uniform current. Measured in the
harbour, the WAM-V's track stayed within 1.45 m of that path over a 60 s episode and 6.3 m
over 100 s (its turn slips, so the current carries it elsewhere): each point's margin grows
with its time. A thrust step cannot be predicted so: a path ends at the first one.
"""

from __future__ import annotations

import numpy as np

from catabot.config.scenario import Scenario, VesselConfig

SAMPLE_S = 0.5  # between two predicted points: a boat at 4 m/s moves 2 m
PATH_MARGIN_M = 3.0  # the prediction's error (dynamics, gusts, waves) added to a footprint
MARGIN_GROWTH = 0.06  # m/s: and more the later the point (3 m + 6 m at 100 s)


def path_points(vessel: VesselConfig, scenario: Scenario, *, seconds: float) -> np.ndarray:
    """(k, 3): map x, y of `vessel` every SAMPLE_S from t = 0 over `seconds`, while its
    script's twists say where it goes, and each point's margin (m)."""
    assert vessel.pose is not None, "poses resolved (placement.resolve_poses)"
    times = np.arange(0.0, seconds + SAMPLE_S, SAMPLE_S)
    x, y, yaw = vessel.pose.x_m, vessel.pose.y_m, vessel.pose.yaw_rad
    out = np.full((times.size, 2), np.nan)
    out[times <= _first_step(vessel, seconds)] = (x, y)
    ends = [*(s.t_s for s in vessel.script), seconds][1:]  # each step until the next
    for step, end in zip(vessel.script, ends, strict=True):
        if step.twist is None:
            break
        span = (times >= step.t_s) & (times <= end)
        u, r = step.twist.surge_mps, step.twist.yaw_rate_radps
        out[span] = _arc(x, y, yaw, u, r, times[span] - step.t_s)
        x, y = _arc(x, y, yaw, u, r, np.array([end - step.t_s]))[0]
        yaw += r * (end - step.t_s)
    kept = ~np.isnan(out[:, 0])
    drift = np.asarray(scenario.water.current.velocity_mps)[None, :] * times[kept, None]
    margin = PATH_MARGIN_M + MARGIN_GROWTH * times[kept, None]
    return np.hstack([out[kept] + drift, margin])


def _first_step(vessel: VesselConfig, seconds: float) -> float:
    """Until its first step a vessel rests where it starts."""
    return vessel.script[0].t_s if vessel.script else seconds


def _arc(x: float, y: float, yaw: float, u: float, r: float, t: np.ndarray) -> np.ndarray:
    """Positions after `t` seconds at surge `u` and yaw rate `r` from (x, y, yaw)."""
    if abs(r) < 1e-9:
        return np.stack([x + u * t * np.cos(yaw), y + u * t * np.sin(yaw)], axis=1)
    k = u / r
    heading = yaw + r * t
    return np.stack(
        [x + k * (np.sin(heading) - np.sin(yaw)), y - k * (np.cos(heading) - np.cos(yaw))], axis=1
    )
