"""Read a TOML file into a validated pydantic model, with errors a person can act on.

Every failure becomes one :class:`~shared.errors.ConfigError` line of the form
``<file>: <key>: <what was expected> (got <value>)``, e.g.::

    config/station.toml: programs[0].target_force_n: Input should be greater than 0 (got -5)
    config/station.toml: can.chanel: unknown key; expected one of: channel, dbc, interface, port
"""

from __future__ import annotations

import tomllib
from pathlib import Path
from typing import Any, TypeVar

from pydantic import BaseModel, ConfigDict, ValidationError

from shared.errors import ConfigError
from shared.files import real_path

ModelT = TypeVar("ModelT", bound=BaseModel)


class StrictModel(BaseModel):
    """Base of every configuration section: unknown keys are errors, values immutable."""

    model_config = ConfigDict(extra="forbid", frozen=True)


def read_toml(path: Path) -> dict[str, Any]:
    """Parse ``path`` as TOML; a missing or malformed file is a ConfigError naming it."""
    try:
        with path.open("rb") as handle:
            return tomllib.load(handle)
    except FileNotFoundError as err:
        raise ConfigError(f"{path}: file not found") from err
    except tomllib.TOMLDecodeError as err:
        raise ConfigError(f"{path}: not valid TOML: {err}") from err
    except UnicodeDecodeError as err:
        raise ConfigError(f"{path}: not a text file (byte {err.start}: {err.reason})") from err
    except OSError as err:
        raise ConfigError(f"{path}: cannot be read: {err.strerror}") from err


def validate(model: type[ModelT], data: dict[str, Any], path: Path) -> ModelT:
    """Validate ``data`` against ``model``; the first problem becomes a ConfigError."""
    try:
        return model.model_validate(data, context={"source": path})
    except ValidationError as err:
        raise ConfigError(describe_validation_error(err, model, path)) from err


def describe_validation_error(err: ValidationError, model: type[BaseModel], path: Path) -> str:
    """One line, ``file: key: message (got value)``; more problems follow, ``; ``-separated,
    missing and unknown keys of one table named together (an empty file:
    ``file: station, can, zenoh, programs, recorder: Field required``)."""
    parts: list[str | tuple[str, tuple[int | str, ...]]] = []
    grouped: dict[tuple[str, tuple[int | str, ...]], list[str]] = {}
    for problem in err.errors():
        location = problem["loc"]
        key = dotted_key(location)
        if problem["type"] in ("extra_forbidden", "missing"):
            group = (problem["type"], location[:-1])
            if group not in grouped:
                grouped[group] = []
                parts.append(group)
            grouped[group].append(key)
            continue
        message = " ".join(problem["msg"].removeprefix("Value error, ").split())
        got = problem.get("input")
        shown = "" if isinstance(got, dict) else f" (got {got!r})"
        parts.append(f"{key or '(top level)'}: {message}{shown}")
    lines = [
        part if isinstance(part, str) else _group_line(part, grouped[part], model) for part in parts
    ]
    return f"{path}: " + "; ".join(lines)


def _group_line(
    group: tuple[str, tuple[int | str, ...]], keys: list[str], model: type[BaseModel]
) -> str:
    kind, table = group
    if kind == "missing":
        return f"{', '.join(keys)}: Field required"
    allowed = allowed_keys(model, table)
    hint = f"; expected one of: {', '.join(allowed)}" if allowed else ""
    return f"{', '.join(keys)}: unknown key{'s' if len(keys) > 1 else ''}{hint}"


def dotted_key(location: tuple[int | str, ...]) -> str:
    """``("programs", 0, "target_force_n")`` -> ``programs[0].target_force_n``."""
    text = ""
    for part in location:
        if isinstance(part, int):
            text += f"[{part}]"
        else:
            text += f".{part}" if text else str(part)
    return text


def allowed_keys(model: type[BaseModel], location: tuple[int | str, ...]) -> list[str]:
    """The field names of the (sub)model found by walking ``location`` from ``model``."""
    current: Any = model
    for part in location:
        if isinstance(part, int):
            continue
        is_model = isinstance(current, type) and issubclass(current, BaseModel)
        field = current.model_fields.get(part) if is_model else None
        if field is None:
            return []
        current = _model_in(field.annotation)
        if current is None:
            return []
    if isinstance(current, type) and issubclass(current, BaseModel):
        return sorted(current.model_fields)
    return []


def _model_in(annotation: Any) -> type[BaseModel] | None:
    """The BaseModel inside ``X``, ``list[X]``, ``X | None`` annotations, if any."""
    if isinstance(annotation, type) and issubclass(annotation, BaseModel):
        return annotation
    for argument in getattr(annotation, "__args__", ()):
        found = _model_in(argument)
        if found is not None:
            return found
    return None


def resolve_relative(path: Path, base_file: Path) -> Path:
    """A path from a config file, taken relative to that file's folder when not absolute
    (its links followed; one that never ends left for what reads the path to name)."""
    return path if path.is_absolute() else real_path(base_file.parent / path)
