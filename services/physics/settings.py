"""Run-time settings that physics owns: the global wind, the uniform current, the sea.

Each change arrives with the Tick of the step it takes effect in (catabot/bus/settings.py)
and is applied before that step, in the order given, by physics and sensors alike (the sea:
both must agree on the surface at every tick, as it builds up).
"""

from __future__ import annotations

from collections.abc import Iterable

from catabot.bus.settings import Change
from catabot.config import live
from catabot.config.scenario import Scenario
from catabot.world.sea_change import SeaChange
from catabot.world.waves import WaveField
from services.physics.world import PhysicsWorld


def take(
    world: PhysicsWorld,
    scenario: Scenario,
    specs: dict[str, live.Spec],
    changes: Iterable[Change],
    *,
    tick: int,
    sea: SeaChange,
) -> None:
    """A tick's changes, then the sea's stage at that tick, if one falls there."""
    for change in changes:
        apply(world, scenario, specs, change, sea=sea)
    waves = sea.at(tick)
    if waves is not None:
        world.set_waves(waves)


def apply(
    world: PhysicsWorld,
    scenario: Scenario,
    specs: dict[str, live.Spec],
    change: Change,
    *,
    sea: SeaChange,
) -> None:
    """Apply one change if it is physics' (other keys are other services'); a new sea
    builds up from this tick on (`sea.at`, every tick: catabot/world/sea_change.py)."""
    spec = specs.get(change.key)
    kind, value = (spec.kind if spec else ""), change.decoded
    wind = world.loads.wind
    if kind == "wind.speed_mps" and wind is not None:
        wind.set_global(speed_mps=float(value))
    elif kind == "wind.toward_rad" and wind is not None:
        wind.set_global(toward_rad=float(value))
    elif kind == "current":
        world.loads.set_uniform_current((float(value[0]), float(value[1])))
    elif kind == "waves":
        sea.begin(WaveField(live.wave_config(scenario, value), scenario.seed), tick=change.tick)
        return
    else:
        return
    world.wake()  # the loads changed: resting buoys move again
