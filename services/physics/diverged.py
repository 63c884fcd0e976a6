"""A state that stops being finite, named: which body, when, and which load drove it there
(dm_control's `check_invalid_state`, with the cause). One NaN would otherwise spread
through contacts to every body and reach the sensors and the recording unnoticed."""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np
from numpy.typing import NDArray

from catabot.errors import CataBotError

Array = NDArray[np.float64]


class PhysicsDiverged(CataBotError, FloatingPointError):
    """The simulation left the numbers: the message names the body and the load."""


def check_finite(
    ids: Sequence[str], loads: Mapping[str, Array], generalized: Array, time_s: float
) -> None:
    """Before DART steps: DART zeroes a non-finite acceleration and goes on, which would hide
    the fault (a body frozen in place), so a load that is not finite stops the run here."""
    if np.isfinite(generalized).all():
        return
    bad = np.asarray(~np.isfinite(generalized).all(axis=1))
    raise diverged(ids, bad, loads, time_s, "a load on it")


def check_state(
    ids: Sequence[str], pos: Array, vel: Array, loads: Mapping[str, Array], time_s: float
) -> None:
    """After DART steps: finite loads may still throw a body out of the numbers."""
    if np.isfinite(pos).all() and np.isfinite(vel).all():
        return
    ok = np.isfinite(pos).all(axis=1) & np.isfinite(vel).all(axis=1)
    if not ok.all():
        raise diverged(ids, np.asarray(~ok), loads, time_s, "its state")


def diverged(
    ids: Sequence[str], bad: NDArray[np.bool_], loads: Mapping[str, Array], time_s: float,
    what: str,
) -> PhysicsDiverged:  # fmt: skip
    """The error for the first bad body: the loads on it in that step, the largest named."""
    row = int(np.flatnonzero(bad)[0])
    forces = {kind: float(np.linalg.norm(w[row, :3])) for kind, w in loads.items()}
    worst = max(forces, key=lambda k: forces[k] if np.isfinite(forces[k]) else np.inf)
    listed = ", ".join(f"{kind} {f:.3g} N" for kind, f in forces.items())
    return PhysicsDiverged(
        f"body {ids[row]!r}: {what} is not finite at t = {time_s:.2f} s; the largest load on "
        f"it in that step was {worst} ({listed}); {int(bad.sum())} bodies diverged"
    )
