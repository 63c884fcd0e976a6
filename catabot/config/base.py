"""What every configuration model shares: strictness, and one way to explain what is wrong.

Every scenario section and file format (vessel models, waves, terrain, sensors, traffic)
derives from `Strict`: unknown keys are errors (a misspelt key must not be silently
ignored), values are frozen, and NaN or infinity is refused. `explain` turns pydantic's
errors into one line per problem naming the dotted field, the rule and the value.
"""

from __future__ import annotations

import difflib
import json
import math
from collections.abc import Iterable
from functools import cache, partial
from pathlib import Path
from types import UnionType
from typing import Annotated, Any, Union, get_args, get_origin

from pydantic import (
    AfterValidator,
    BaseModel,
    ConfigDict,
    Field,
    StrictInt,
    ValidationError,
    model_validator,
)
from pydantic_core import PydanticCustomError

from catabot.bus.keys import check_name
from catabot.errors import CataBotError

Seed = Annotated[
    StrictInt,
    Field(ge=0, lt=2**63, description="an integer in [0, 2**63): seeds every random source"),
]
"""A seed (catabot.world.seeding): JSON integers only (3.0, "3" or true are refused)."""


def _radians(value: float) -> float:
    if abs(value) > 2.0 * math.pi:
        raise ValueError(f"angles are radians, within ±2π{degrees_hint(value)}")
    return value


def degrees_hint(value: float) -> str:
    """A radians value that may be degrees, said one way for every such field."""
    return f" (degrees? {value:g}° is {math.radians(value):.4g} rad)"


Angle = Annotated[float, AfterValidator(_radians)]
"""A heading or direction in radians; beyond ±2π it is a unit mistake, not a turn."""


WorldName = Annotated[str, AfterValidator(partial(check_name, "world"))]
VesselId = Annotated[str, AfterValidator(partial(check_name, "vessel"))]
BuoyId = Annotated[str, AfterValidator(partial(check_name, "buoy"))]
SensorName = Annotated[str, AfterValidator(partial(check_name, "sensor"))]
ParticipantName = Annotated[str, AfterValidator(partial(check_name, "participant"))]
"""Names that become one chunk of a key expression (and part of file names)."""


def did_you_mean(word: str, choices: Iterable[str]) -> str:
    """ "did you mean 'x'?" for the choice a typo is nearest, or "" when none is near."""
    near = difflib.get_close_matches(word, list(choices), n=1)
    return f"did you mean {near[0]!r}?" if near else ""


def unique(items: list[Any], *, attr: str, what: str) -> list[Any]:
    """`items` if no two share `attr` (ids that would share keys and files)."""
    names = [getattr(item, attr) for item in items]
    if len(set(names)) != len(names):
        raise ValueError(f"{what} must be unique (got {names})")
    return items


class ConfigError(CataBotError, ValueError):
    """A configuration (scenario, model file, section) that cannot be used; names the field."""


class ScenarioError(ConfigError):
    """A scenario that cannot run; the message names the file, field and allowed values."""


class Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)

    @model_validator(mode="before")
    @classmethod
    def _numbers_are_numbers(cls, data: Any) -> Any:
        """pydantic's lax mode reads true as 1 and "10" as 10: `"rate_mm_h": true` would run
        in rain, and a schema-driven editor, which says `number`, would disagree with us.
        Such a value is swapped for a `NotANumber`, which pydantic then refuses where it is
        (with every other problem of the file, and its list index)."""
        if not isinstance(data, dict):
            return data
        swapped = {k: _swapped(v) if _number_kind(cls, k) else v for k, v in data.items()}
        return swapped if any(swapped[k] is not data[k] for k in data) else data


class NotANumber:
    """A true, false or text where a number belongs, shown as the JSON it was."""

    def __init__(self, value: bool | str) -> None:
        self.value = value

    def __repr__(self) -> str:
        if isinstance(self.value, bool):
            return json.dumps(self.value)
        return f"the text {json.dumps(self.value)}"


def _swapped(value: Any) -> Any:
    """`value`, or a copy, with each true, false or text (in it) as a `NotANumber`."""
    if isinstance(value, list | tuple):
        items = [_swapped(v) for v in value]
        return items if any(a is not b for a, b in zip(items, value, strict=True)) else value
    return NotANumber(value) if isinstance(value, bool | str) else value


@cache
def _number_kind(model: type[BaseModel], field: str) -> str | None:
    """'integer' or 'number' when a field takes only those (or lists of them), else None."""
    if field not in model.model_fields:
        return None
    kinds = _leaves(model.model_fields[field].annotation)
    if not kinds or not kinds <= {int, float}:
        return None
    return "integer" if kinds == {int} else "number"


def _leaves(annotation: Any) -> set[Any]:
    """The scalar types an annotation is made of (Annotated, unions, tuples, lists opened)."""
    origin, args = get_origin(annotation), get_args(annotation)
    if origin is Annotated:
        return _leaves(args[0])
    if origin in (Union, UnionType, tuple, list):
        kinds = [a for a in args if a not in (type(None), Ellipsis)]
        return set().union(*(_leaves(a) for a in kinds)) if kinds else {object}
    return {annotation}


class FieldProblem(ValueError):
    """Raised by a cross-field validator so the message can name the offending field."""

    def __init__(self, field: str, message: str) -> None:
        super().__init__(message)
        self.field = field


_BOUNDS = {
    "greater_than": ">",
    "greater_than_equal": ">=",
    "less_than": "<",
    "less_than_equal": "<=",
}


_TYPES = {
    "int_type": "an integer",
    "int_parsing": "an integer",
    "int_from_float": "an integer",
    "float_type": "a number",
    "float_parsing": "a number",
    "bool_type": "true or false",
    "bool_parsing": "true or false",
    "string_type": "a string",
    "list_type": "a list",
    "dict_type": "an object",
    "model_type": "an object",
    "tuple_type": "a list",
}


def explain(exc: ValidationError, *, model: type[BaseModel], where: str = "") -> str:
    """One line per problem, joined by '; ': `path.to.field: rule (got value)`."""
    lines = [describe(err, model=model, where=where) for err in _short_tuples(exc.errors())]
    return "; ".join(_allowed_once(list(dict.fromkeys(lines))))


UNKNOWN = ": unknown field (allowed: "


def _allowed_once(lines: list[str]) -> list[str]:
    """Unknown fields of one place said together, its allowed names once: a file with 20
    misnamed keys repeated the list 20 times (4 kB on one line)."""
    paths: dict[str, list[str]] = {}
    for line in lines:
        path, found, allowed = line.partition(UNKNOWN)
        if found:
            paths.setdefault(allowed, []).append(path)
    out = []
    for line in lines:
        path, found, allowed = line.partition(UNKNOWN)
        if found and path == paths[allowed][0] and len(paths[allowed]) > 1:
            line = f"{', '.join(paths[allowed])}: unknown fields (allowed: {allowed}"
        if not found or path == paths[allowed][0]:
            out.append(line)
    return out


def _short_tuples(errors: list[Any]) -> list[Any]:
    """A vector given too few values is one problem ("needs 3 values, got 2"), not one
    "required field missing" per absent index (`antenna_offset.2`)."""
    out: list[Any] = []
    wanted: dict[tuple[Any, ...], int] = {}
    for err in errors:
        loc, got = err["loc"], err.get("input")
        if (
            err["type"] == "missing"
            and loc
            and isinstance(loc[-1], int)
            and isinstance(got, list | tuple)
        ):
            wanted[loc[:-1]] = max(wanted.get(loc[:-1], 0), loc[-1] + 1)
            err = {**err, "loc": loc[:-1], "type": "short_vector", "ctx": {"got": len(got)}}
        out.append(err)
    for err in out:
        if err["type"] == "short_vector":
            err["ctx"]["wanted"] = wanted[err["loc"]]
    return out


def describe(err: Any, *, model: type[BaseModel], where: str = "") -> str:
    loc = [str(p) for p in err["loc"]]
    ctx, kind, got = err.get("ctx") or {}, err["type"], err.get("input")
    problem = ctx.get("error")
    if isinstance(problem, FieldProblem):
        return ".".join([*filter(None, [where]), *loc, problem.field]) + f": {problem}"
    path = ".".join([*filter(None, [where]), *loc]) or "(top level)"
    shown = "" if isinstance(got, dict | list) else f" (got {_short(got)})"
    if kind == "missing":
        return f"{path}: required field missing"
    if kind == "short_vector":
        return f"{path}: needs {ctx['wanted']} values, got {ctx['got']}"
    if kind == "extra_forbidden":
        allowed = ctx.get("allowed") or ", ".join(_allowed_fields(model, err["loc"][:-1]))
        return f"{path}{UNKNOWN}{allowed})"
    if kind == "literal_error":
        return f"{path}: must be one of {ctx.get('expected')}{shown}"
    if kind in _BOUNDS:
        bound = next(v for k, v in ctx.items() if k in ("gt", "ge", "lt", "le"))
        limit = str(bound) if isinstance(bound, int) else f"{bound:g}"
        return f"{path}: must be {_BOUNDS[kind]} {limit}{shown}{_degrees(path, got)}"
    if kind in _TYPES:
        return f"{path}: must be {_TYPES[kind]}{shown}{_nanoseconds(path, got)}"
    if kind in ("too_short", "too_long"):
        most = "at least" if kind == "too_short" else "at most"
        count = ctx.get("min_length" if kind == "too_short" else "max_length")
        return f"{path}: needs {most} {count} item(s), got {ctx.get('actual_length')}"
    if kind == "finite_number":
        return f"{path}: must be a finite number{shown}"
    return f"{path}: {str(err['msg']).removeprefix('Value error, ')}{shown}"


def _nanoseconds(path: str, got: Any) -> str:
    """A fraction given to a `_ns` field was meant in seconds (`dt_ns: 0.01`): say so."""
    if not path.endswith("_ns") or not isinstance(got, float) or not 0 < got < 1e3:
        return ""
    return f"; {path.rsplit('.', 1)[-1]} is in nanoseconds: {got:g} s is {round(got * 1e9)}"


def _degrees(path: str, got: Any) -> str:
    """Degrees given to a bounded `_rad` field (`roll_rad: 30`), said as an Angle's are."""
    if not path.endswith("_rad") or not isinstance(got, int | float) or isinstance(got, bool):
        return ""
    return degrees_hint(got)


def _short(value: Any) -> str:
    """A value as shown in a message: its repr, cut short (a 10,000-character name); the
    file's own words for what JSON spells differently (null, true, false)."""
    if value is None or isinstance(value, bool):
        return json.dumps(value)
    text = repr(value)
    return text if len(text) <= 80 else text[:77] + "..."


def naming_allowed(exc: ValidationError, *, model: type[BaseModel]) -> ValidationError:
    """`exc` with each unknown field's allowed names found in `model` now: raised again
    inside a field such as a sensor's free-form `params`, its errors are explained against
    the scenario, where the walk to the field cannot see the model that refused it."""
    errors: list[Any] = []
    for err in exc.errors():
        line = {k: err[k] for k in ("type", "loc", "input")} | {"ctx": err.get("ctx") or {}}
        if err["type"] == "extra_forbidden":
            allowed = {"allowed": ", ".join(_allowed_fields(model, err["loc"][:-1]))}
            line["type"] = PydanticCustomError("extra_forbidden", "unknown field", allowed)
        errors.append(line)
    return ValidationError.from_exception_data(exc.title, errors)


def _allowed_fields(model: type[BaseModel], loc: tuple[Any, ...]) -> list[str]:
    """Field names of the model found by walking `loc` from `model` (for unknown keys); in
    a tagged union (a list of parts told apart by `type`) the tag in `loc` picks the member."""
    models = [model]
    for part in loc:
        if isinstance(part, int):
            continue
        tagged = [m for m in models if part in _tags(m)]
        if tagged:
            models = tagged
            continue
        info = next((m.model_fields[str(part)] for m in models if part in m.model_fields), None)
        nested = _models_in(info.annotation) if info is not None else []
        if not nested:
            break
        models = nested
    return list(models[0].model_fields)


def _models_in(annotation: Any) -> list[type[BaseModel]]:
    """The BaseModel classes inside an annotation such as `list[Hull]` or `A | B`."""
    if isinstance(annotation, type) and issubclass(annotation, BaseModel):
        return [annotation]
    args = getattr(annotation, "__args__", ()) or ()
    return [m for arg in args for m in _models_in(arg)]


def _tags(model: type[BaseModel]) -> tuple[Any, ...]:
    """The values of a model's `type: Literal[...]` field (its tag in a tagged union)."""
    info = model.model_fields.get("type")
    return get_args(info.annotation) if info is not None else ()


MAX_FILE_BYTES = 64 * 2**20  # a scenario is a page of JSON; a bigger file is a mistake


def read_json(file: Path, *, what: str, error: type[ConfigError] = ScenarioError) -> Any:
    """A JSON file's data; `error` naming the file for anything that is not JSON text
    (unreadable, not UTF-8, too big, nested deeper than the parser can follow)."""
    try:
        if file.stat().st_size > MAX_FILE_BYTES:
            raise error(f"{what} {file}: over {MAX_FILE_BYTES // 2**20} MiB, not a scenario")
        text = file.read_bytes().decode("utf-8")
        return json.loads(text)
    except OSError as exc:
        raise error(f"{what} {file}: cannot read: {exc.strerror}") from None
    except UnicodeDecodeError as exc:
        raise error(f"{what} {file}: not UTF-8 text (byte {exc.start})") from None
    except json.JSONDecodeError as exc:
        raise error(f"{what} {file}: not valid JSON: {exc}") from None
    except RecursionError:
        raise error(f"{what} {file}: JSON nested too deeply") from None
