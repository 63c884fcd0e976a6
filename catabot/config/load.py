"""Scenario files (DESIGN.md §6): JSON in, a validated `Scenario` out.

Validation happens before any process starts, and every error names the field and what is
allowed, because a typo found after a ten-minute run is a lost ten minutes. Files in the
original simulator's `SettingsConfig.json` format are mapped by `settings_config`.
"""

from __future__ import annotations

import hashlib
import json
import os
from pathlib import Path, PurePath
from typing import Any

from pydantic import ValidationError

from catabot.config import overrides
from catabot.config.base import ScenarioError, did_you_mean, explain, read_json
from catabot.config.rates import check_rates
from catabot.config.scenario import Scenario
from catabot.config.sensors import SENSOR_TYPES
from catabot.config.settings_config import is_settings_config, map_settings_config
from catabot.config.vessel import VesselModel

BUNDLED = Path(__file__).parents[1] / "data" / "scenarios"
TERRAINS = BUNDLED.parent / "terrain"  # elevation images a scenario may name bare: "bay.png"


def parse_scenario(data: Any, *, source: str = "<data>") -> Scenario:
    if isinstance(data, dict) and is_settings_config(data):
        data = map_settings_config(data, source=source)
    if isinstance(data, dict) and isinstance(data.get("$schema"), str):  # an editor's hook
        data = {k: v for k, v in data.items() if k != "$schema"}
    try:
        scenario = Scenario.model_validate(data)
    except ValidationError as exc:
        raise ScenarioError(f"scenario {source}: {explain(exc, model=Scenario)}") from None
    try:
        check_rates(scenario)
    except ScenarioError as exc:  # named like every other scenario error: which file
        raise ScenarioError(f"scenario {source}: {exc}") from None
    return scenario


def with_sets(
    data: dict[str, Any], items: list[str], *, source: str, flagged: dict[str, str]
) -> list[str]:
    """`--set`'s changes made to `data` (a scenario's own), each path checked against the
    scenario it makes now, defaults filled (overrides.py); the flags, as messages name them.
    `flagged`: fields a flag of their own gives (`--seed`, generate's `--boats`)."""
    resolved = parse_scenario(data, source=source).model_dump(mode="json")
    return overrides.apply(data, items, resolved=resolved, flagged=flagged)


def load_scenario(path: str | Path | None = None) -> Scenario:
    """Load a scenario file, or the bundled default when `path` is None."""
    data, file = scenario_data(path)
    return parse_scenario(data, source=str(file))


def scenario_data(path: str | Path | None = None) -> tuple[Any, Path]:
    """A scenario file's own data, its paths made absolute, and the file (`--set` changes
    the data before it is parsed: catabot/config/overrides.py)."""
    file = BUNDLED / "default.json" if path is None else Path(path)
    if not file.is_file():
        bundled = BUNDLED / f"{file.name}.json"
        if path is not None and "/" not in str(path) and bundled.is_file():
            file = bundled
        elif file.is_dir():
            inside = file / "scenario.json"  # a run folder: replaying it is the likely wish
            hint = f"; a run folder's scenario is {inside}" if inside.is_file() else ""
            raise ScenarioError(f"scenario file {str(file)!r} is a folder{hint}")
        else:
            raise ScenarioError(f"scenario file {str(file)!r} does not exist{_bundled_hint(path)}")
    data = read_json(file, what="scenario")
    if isinstance(data, dict) and is_settings_config(data):  # first: its paths are relative too
        data = map_settings_config(data, source=str(file))
    return absolute_paths(data, file.parent.resolve()), file


def _bundled_hint(path: str | Path | None) -> str:
    """A bare name is a bundled scenario's: name the one it is near, and all of them."""
    if path is None or "/" in str(path) or str(path).endswith(".json"):
        return ""
    names = sorted(p.stem for p in BUNDLED.glob("*.json"))
    ask = did_you_mean(str(path), names)
    return f" ({ask + ' ' if ask else ''}bundled scenarios: {', '.join(names)})"


def scenario_json(scenario: Scenario) -> str:
    """A run folder's scenario.json text: `catabot run` writes it, the recorder compares a
    folder's with it, and the applied settings are written back in it (one format)."""
    return scenario.model_dump_json(indent=2) + "\n"


def absolute_paths(data: Any, base: Path) -> Any:
    """Input files named relative to the scenario become absolute, so the resolved copy in
    the run folder (and every service reading it) finds the same files."""
    if not isinstance(data, dict):
        return data
    data = json.loads(json.dumps(data))
    terrain = _node(data, "terrain")
    _absolute(terrain, "elevation_image", base, bundled=TERRAINS)
    _bundled_scale(terrain)
    _absolute(_node(data, "water", "current", "map"), "path", base)
    vessels = data.get("vessels")
    for vessel in vessels if isinstance(vessels, list) else []:
        if isinstance(vessel, dict) and str(vessel.get("model", "")).endswith(".json"):
            _absolute(vessel, "model", base)
        _program(_node(vessel, "controller") if isinstance(vessel, dict) else {}, base)
    return data


def _node(data: dict[str, Any], *path: str) -> dict[str, Any]:
    for key in path:
        child = data.get(key)
        if not isinstance(child, dict):
            return {}
        data = child
    return data


def _absolute(node: dict[str, Any], key: str, base: Path, *, bundled: Path | None = None) -> None:
    """node[key] relative to `base`, without `..` parts; a bare name that is not there but
    is a bundled file (`bay.png`) names that one, so a bundled scenario copied elsewhere
    still runs."""
    if not isinstance(node.get(key), str):
        return
    path = Path(os.path.normpath(base / Path(node[key]).expanduser()))
    named = Path(node[key]).name == node[key]
    if bundled is not None and named and not path.exists() and (bundled / node[key]).is_file():
        path = bundled / node[key]
    node[key] = str(path)


def _bundled_scale(terrain: dict[str, Any]) -> None:
    """A bundled image's own heights and scale where the scenario gives none (`bay.json`
    beside `bay.png`, the harbour's): a PNG carries none, and the defaults (5 m a pixel, -35
    to 60 m) made `"bay.png"` alone a bay 2.5 times the harbour's."""
    image = terrain.get("elevation_image")
    if not isinstance(image, str) or Path(image).resolve().parent != TERRAINS.resolve():
        return
    sidecar = Path(image).with_suffix(".json")
    for key, value in (json.loads(sidecar.read_text()) if sidecar.is_file() else {}).items():
        terrain.setdefault(key, value)


def _program(controller: dict[str, Any], base: Path) -> None:
    """A controller's program: next to the scenario file if it is there, else from the
    current directory (`examples/navigate.py` from the repository root); left as written
    when neither has it, for `catabot run` to refuse by name (catabot/run/programs.py)."""
    program = controller.get("program")
    if not isinstance(program, str) or not program:
        return
    for folder in (base, Path.cwd()):
        path = folder / Path(program).expanduser()
        if path.is_file():
            controller["program"] = str(path.resolve())
            return


def json_schema() -> dict[str, Any]:
    """The scenario's JSON Schema, for editors (`catabot scenario schema`)."""
    schema = _titled(Scenario.model_json_schema(), "CataBot scenario")
    _sensor_params(schema)
    schema["properties"]["$schema"] = {"type": "string", "description": "this schema's path or "
                                       "URL, for an editor (ignored by CataBot)"}  # fmt: skip
    return schema


def model_schema() -> dict[str, Any]:
    """A vessel model file's JSON Schema (`catabot scenario model-schema`): its fields were
    documented only by the bundled files and the errors."""
    return _titled(VesselModel.model_json_schema(), "CataBot vessel model")


def _titled(schema: dict[str, Any], title: str) -> dict[str, Any]:
    return schema | {"$schema": "https://json-schema.org/draft/2020-12/schema", "title": title}


def _sensor_params(schema: dict[str, Any]) -> None:
    """Each sensor's `params` against its type's own model: pydantic sees a free dict there
    (the type picks the model when it validates), which left an editor nothing to complete
    or check."""
    defs, cases = schema["$defs"], []
    for name, spec in SENSOR_TYPES.items():
        own = spec.params.model_json_schema(ref_template="#/$defs/{model}")
        defs.update(own.pop("$defs", {}))
        defs[spec.params.__name__] = own
        ref = {"$ref": f"#/$defs/{spec.params.__name__}"}
        cases.append({"if": {"properties": {"type": {"const": name}}, "required": ["type"]},
                      "then": {"properties": {"params": ref}}})  # fmt: skip
    defs["SensorConfig"]["allOf"] = cases


FILE_SUFFIXES = (".png", ".tif", ".tiff", ".json", ".obj", ".stl", ".gltf", ".glb")


def digest(scenario: Scenario) -> str:
    """12 hex digits of the scenario every process of a run must hold alike: hosts given
    different files (a pose, a rate, dt) would each simulate a world of their own, and the
    run would end as if nothing were wrong. Files count by name only: each machine may keep
    its data in a folder of its own."""
    data = _names_only(scenario.model_dump(mode="json"))
    text = json.dumps(data, sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode()).hexdigest()[:12]


def _names_only(value: Any) -> Any:
    if isinstance(value, dict):
        return {k: _names_only(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_names_only(v) for v in value]
    if isinstance(value, str) and value.lower().endswith(FILE_SUFFIXES):
        return PurePath(value).name
    return value
