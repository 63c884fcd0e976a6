"""Run-time settings (the original simulator's settings menu): which keys a scenario offers,
which values each allows, and the scenario's `settings` timeline.

A key names one setting of one scenario; the value is checked by the same pydantic model
that checks it in the scenario file, so `catabot set rain 80` is refused with the rule the
scenario file would give. Keys are looked up, never parsed: vessel and sensor names may
contain '.', so `sensor.<vessel>.<sensor>.enabled` is found in the table of this scenario's
keys. The canonical JSON text of a validated value (`canonical`) is what the clock carries
and the run folder records, so a change made live and the same change from the timeline
reach every service as the same bytes.
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Annotated, Any

from pydantic import BaseModel, Field, JsonValue, ValidationError

from catabot.bus.clock import NS_PER_S
from catabot.bus.settings import Change, switch_key
from catabot.config.base import ConfigError, FieldProblem, Strict, describe, did_you_mean
from catabot.config.environment import CurrentConfig, RainConfig, WindConfig
from catabot.config.sensors import CameraOutputs
from catabot.config.traffic import BEHAVIOURS, Behaviour
from catabot.config.waves import PRESETS, WaveConfig

if TYPE_CHECKING:
    from catabot.config.scenario import Scenario

OUTPUTS = tuple(CameraOutputs.model_fields)
MAX_KEY_CHARS = 200


class SettingError(ConfigError):
    """A setting key this scenario does not offer, or a value its key does not allow."""


class SettingChange(Strict):
    """One entry of the scenario's `settings` timeline: from `t_s` on, `key` is `value`
    (applied at the start of the first tick at or after `t_s`; `catabot get` lists keys)."""

    t_s: float = Field(ge=0)
    key: Annotated[str, Field(min_length=1, max_length=MAX_KEY_CHARS)]
    value: JsonValue


@dataclass(frozen=True)
class Spec:
    """What a key sets: `kind` (rain, wind.speed_mps, wind.toward_rad, current, waves,
    enabled, output, behaviour), the vessel or boat and the sensor or output it names."""

    kind: str
    allowed: str
    owner: str = ""  # vessel id (sensors) or boat id (traffic)
    name: str = ""  # sensor name
    output: str = ""  # camera output


GLOBAL = {
    "rain": Spec("rain", "a rate in mm/h from 0 to 50 (the scenario's rain.rate_mm_h)"),
    "wind.speed_mps": Spec("wind.speed_mps", "a speed in m/s from 0 to 80"),
    "wind.toward_rad": Spec(
        "wind.toward_rad", "an angle in rad the wind blows toward (0 east, 1.5708 north)"
    ),
    "current": Spec(
        "current", "[east, north] in m/s, at most 10 m/s (the scenario's water.current)"
    ),
    "waves": Spec("waves", f"a wave preset: one of {', '.join(map(repr, PRESETS))}"),
}
ON_OFF = "true or false"


# A sea with waves makes the sensors load their compiled wave kernels as it is set: numba
# compiles them in ≈10 s where its cache is cold (a run that started calm; `make` warms it),
# longer on a slow machine. The clock gives that tick this much more than its deadline.
WAVES_GRACE_S = 120.0


def apply_grace_s(key: str) -> float:
    """How much longer than the per-tick deadline a change of `key` may take to apply."""
    return WAVES_GRACE_S if key == "waves" else 0.0


def keys_of(scenario: Scenario) -> dict[str, Spec]:
    """Every key this scenario offers, in a stable order."""
    keys = dict(GLOBAL)
    for vessel in scenario.vessels:
        for sensor in vessel.sensors:
            base = f"sensor.{vessel.id}.{sensor.name}"  # its outputs; switch_key: on and off
            keys[switch_key(vessel.id, sensor.name)] = Spec(
                "enabled", ON_OFF, vessel.id, sensor.name
            )
            if sensor.type == "camera":
                for out in OUTPUTS:
                    keys[f"{base}.outputs.{out}"] = Spec(
                        "output", ON_OFF, vessel.id, sensor.name, out
                    )
    behaviours = f"one of {', '.join(map(repr, BEHAVIOURS))}"
    for boat in scenario.traffic.boat_ids:
        keys[f"traffic.{boat}.behaviour"] = Spec("behaviour", behaviours, boat)
    return keys


def spec_of(scenario: Scenario, key: str) -> Spec:
    """The key's spec; SettingError naming the keys this scenario offers."""
    spec = keys_of(scenario).get(key) if isinstance(key, str) else None
    if spec is None:
        shown = repr(key) if len(repr(key)) <= 80 else repr(key)[:77] + "..."
        near = did_you_mean(key, keys_of(scenario)) if isinstance(key, str) else ""
        hint = f" ({near})" if near else ""
        raise SettingError(
            f"unknown setting {shown}{hint}; this run's settings: {allowed_keys(scenario)}"
        )
    return spec


def allowed_keys(scenario: Scenario, *, limit: int = 12) -> str:
    """The keys, with the patterns first so that 100 boats do not bury the rest."""
    keys = list(keys_of(scenario))
    shown = ", ".join(keys[:limit])
    more = len(keys) - limit
    return shown + (f" and {more} more (catabot get lists them all)" if more > 0 else "")


def check(scenario: Scenario, key: str, value: Any) -> str:
    """The canonical JSON text of `value` for `key`; SettingError naming what is allowed."""
    spec = spec_of(scenario, key)
    if spec.kind in NUMBERS and _has_bool(value):  # pydantic's lax floats took true as 1.0
        raise SettingError(
            f"{key}: {_short(value)} is not allowed (a number, not true or false); "
            f"allowed: {spec.allowed}"
        )
    try:
        checked = _validated(scenario, spec, value)
    except ValidationError as exc:
        why = describe(exc.errors()[0], model=BaseModel).split(": ", 1)[-1]
        raise SettingError(
            f"{key}: {_short(value)} is not allowed ({why}); allowed: {spec.allowed}"
        ) from None
    return canonical(checked)


def _validated(scenario: Scenario, spec: Spec, value: Any) -> Any:
    """The value through the scenario's own model of that setting."""
    kind = spec.kind
    if kind == "rain":
        return RainConfig.model_validate({"rate_mm_h": value}).rate_mm_h
    if kind in ("wind.speed_mps", "wind.toward_rad"):
        name = kind.split(".")[1]
        return getattr(WindConfig.model_validate({name: value}), name)
    if kind == "current":
        return list(CurrentConfig.model_validate({"velocity_mps": value}).velocity_mps)
    if kind == "waves":
        if not (isinstance(value, str) and value in PRESETS):  # None: valid in a file, not here
            WaveConfig.model_validate({"preset": value if isinstance(value, str) else "?"})
        return wave_config(scenario, value).preset
    if kind in ("enabled", "output"):
        return CameraOutputs.model_validate({"color": value}).color  # a strict bool
    return _Behaviour.model_validate({"behaviour": value}).behaviour


NUMBERS = ("rain", "wind.speed_mps", "wind.toward_rad", "current")  # kinds that take numbers


def _has_bool(value: Any) -> bool:
    return isinstance(value, bool) or (
        isinstance(value, list) and any(isinstance(v, bool) for v in value)
    )


class _Behaviour(Strict):
    behaviour: Behaviour


def wave_config(scenario: Scenario, preset: str) -> WaveConfig:
    """The sea of a preset, travelling the scenario's way (its other fields: the preset's)."""
    return WaveConfig.model_validate(
        {"preset": preset, "direction_rad": scenario.water.waves.direction_rad}
    )


def canonical(value: Any) -> str:
    return json.dumps(value, separators=(",", ":"), sort_keys=True)


def parse_value(text: str) -> Any:
    """A value as typed on the command line: JSON if it is JSON (25, true, [0.5, 0]),
    on/off as booleans, anything else as a string (hold, heavy)."""
    words = {"on": True, "off": False}
    if text.strip().lower() in words:
        return words[text.strip().lower()]
    try:
        return json.loads(text)
    except ValueError as exc:
        if text.lstrip()[:1] in ("[", "{"):  # meant as JSON: say where it is not
            raise SettingError(f"{text!r} is not JSON ({exc}); e.g. [0.3, 0.1]") from None
        return text


AS_PLANNED = "as planned"  # a drawn boat's behaviour before the plan is at hand


def initial_values(scenario: Scenario) -> dict[str, Any]:
    """Every key's value at tick 0 (a boat's behaviour: its override, else "as planned")."""
    overrides = {b.index: b.behaviour for b in scenario.traffic.boats}
    values: dict[str, Any] = {}
    for key, spec in keys_of(scenario).items():
        values[key] = _initial(scenario, spec, overrides)
    return values


def _initial(scenario: Scenario, spec: Spec, overrides: Mapping[int, str | None]) -> Any:
    kind = spec.kind
    if kind == "rain":
        return scenario.rain.rate_mm_h
    if kind == "wind.speed_mps":
        return scenario.wind.speed_mps
    if kind == "wind.toward_rad":
        return scenario.wind.toward_rad
    if kind == "current":
        return list(scenario.water.current.velocity_mps)
    if kind == "waves":
        return _sea(scenario.water.waves)
    if kind == "enabled":
        return True
    if kind == "output":
        sensor = next(s for v in scenario.vessels if v.id == spec.owner for s in v.sensors
                      if s.name == spec.name)  # fmt: skip
        return getattr(sensor.typed_params().outputs, spec.output)
    index = scenario.traffic.boat_ids.index(spec.owner)
    return overrides.get(index) or AS_PLANNED


def _sea(waves: WaveConfig) -> str:
    """The scenario's sea as `catabot get` shows it: its preset, or what its fields make."""
    if waves.preset is not None:
        return waves.preset
    if waves.significant_height_m == 0.0:
        return "calm"
    return f"Hs {waves.significant_height_m:g} m, Tp {waves.peak_period_s:g} s (the scenario's)"


def tick_at(t_s: float, dt_ns: int) -> int:
    """The first tick at or after `t_s` (a recorded change's t_s gives back its tick)."""
    return -(-round(t_s * NS_PER_S) // dt_ns)


def after_end(scenario: Scenario, t_s: float) -> bool:
    """Whether a step at `t_s` (a script's, the timeline's) falls after the run's last tick:
    taken, and never applied (a `--duration` shorter than the file's)."""
    return tick_at(t_s, scenario.dt_ns) >= scenario.ticks


def last_tick_s(scenario: Scenario) -> float:
    return (scenario.ticks - 1) * scenario.dt_ns / NS_PER_S


def timeline(scenario: Scenario) -> list[Change]:
    """The scenario's `settings`, checked and on the clock, in file order within a tick."""
    changes = [
        Change(tick_at(s.t_s, scenario.dt_ns), s.key, check(scenario, s.key, s.value))
        for s in scenario.settings
    ]
    return sorted(changes, key=lambda c: c.tick)  # stable: file order within a tick


def entry(change: Change, dt_ns: int) -> dict[str, Any]:
    """A change as a `settings` entry of the resolved scenario (its tick given back exactly)."""
    return {"t_s": change.tick * dt_ns / NS_PER_S, "key": change.key, "value": change.decoded}


def check_timeline(scenario: Scenario) -> None:
    """Refuse a timeline entry with an unknown key, a bad value or a time that is no time.
    One past the run's end is taken and never applies (the conductor tells it): a sweep's
    `--duration` shorter than the timeline is no mistake in the file, as for scripts."""
    seen: dict[tuple[int, str], int] = {}  # (tick, key): the entry that sets it there
    for i, s in enumerate(scenario.settings):
        if not math.isfinite(s.t_s):
            raise FieldProblem(f"settings.{i}.t_s", f"must be a finite time (got {s.t_s})")
        try:
            check(scenario, s.key, s.value)
        except SettingError as exc:
            raise FieldProblem(f"settings.{i}", str(exc)) from None
        at = (tick_at(s.t_s, scenario.dt_ns), s.key)
        if at in seen:  # the file's order decided it, unsaid (script steps are refused so)
            raise FieldProblem(f"settings.{i}", f"{s.key!r} at {s.t_s:g} s: settings."
                               f"{seen[at]} sets it at the same tick; which should win? give "
                               "one")  # fmt: skip
        seen[at] = i


def _short(value: Any) -> str:
    text = json.dumps(value) if not isinstance(value, str) else repr(value)
    return text if len(text) <= 60 else text[:57] + "..."
