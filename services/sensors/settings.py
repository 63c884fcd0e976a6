"""Run-time settings that the sensors own: the rain, the sea (built up over ticks, as
physics builds it), sensors on and off, and each camera's outputs; applied before the step
of the tick they take effect in."""

from __future__ import annotations

import logging
from collections.abc import Callable, Mapping

from catabot.bus.settings import Change
from catabot.config import live
from catabot.world.sea_change import SeaChange
from catabot.world.waves import WaveField
from catabot.world.world import World
from services.sensors.scene import Scene

log = logging.getLogger("sensors.settings")


class SensorSettings:
    """What is switched: `off` holds the stream keys of sensors turned off."""

    def __init__(
        self, world: World, scene: Scene | None, key_of: Callable[[str, str], str]
    ) -> None:
        self.scenario, self.scene, self.key_of = world.scenario, scene, key_of
        self.sea = SeaChange(world.waves, dt_ns=world.scenario.dt_ns) if scene else None
        self.specs = live.keys_of(self.scenario)
        self.off: set[str] = set()

    def waves(self, tick: int) -> None:
        """The sea from this tick on, where a change builds it up (sea_change.py): after
        the tick's changes, as physics does."""
        waves = self.sea.at(tick) if self.sea is not None else None
        if waves is not None and self.scene is not None:
            self.scene.set_waves(waves)

    def apply(self, change: Change, models: Mapping[str, object]) -> None:
        """Apply one change if it is the sensors' (`models`: each sensor by stream key)."""
        spec = self.specs.get(change.key)
        kind, value = (spec.kind if spec else ""), change.decoded
        if kind == "rain" and self.scene is not None:
            self.scene.rain_rate_mm_h = float(value)  # LiDAR returns and camera streaks
        elif kind == "waves" and self.sea is not None:
            log.info("the sea becomes %r from tick %d on (waves load the compiled wave kernels: "
                     "numba, ≈10 s where its cache is cold)", value, change.tick)  # fmt: skip
            to = WaveField(live.wave_config(self.scenario, value), self.scenario.seed)
            self.sea.begin(to, tick=change.tick)
        elif kind == "enabled" and spec is not None:
            key = self.key_of(spec.owner, spec.name)
            (self.off.discard if value else self.off.add)(key)
        elif kind == "output" and spec is not None:
            camera = models[self.key_of(spec.owner, spec.name)]
            params = camera.params  # type: ignore[attr-defined]
            outputs = params.outputs.model_copy(update={spec.output: bool(value)})
            camera.params = params.model_copy(update={"outputs": outputs})  # type: ignore[attr-defined]
