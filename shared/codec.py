"""JSON encoding of :mod:`shared.messages` and the JSON schema of each type.

The wire format is plain JSON (one object per message, UTF-8). The schema is
derived from the dataclass annotations, so code and schema cannot drift:
``int`` -> integer, ``float`` -> number, ``str`` -> string, ``X | None`` ->
``[X, null]``, ``Literal[...]`` -> enum, nested dataclasses and lists nest.
"""

from __future__ import annotations

import dataclasses
import json
import types
import typing
from functools import cache
from typing import Any, TypeVar

from shared.errors import InputError

MessageT = TypeVar("MessageT")

_JSON_TYPES: dict[type, str] = {int: "integer", float: "number", str: "string", bool: "boolean"}


def encode(message: Any) -> bytes:
    """The JSON bytes of one message (compact, UTF-8)."""
    return json.dumps(to_dict(message), separators=(",", ":")).encode()


def to_dict(message: Any) -> dict[str, Any]:
    """Shallow field dict; nested dataclasses (lists of them too) become dicts."""
    out: dict[str, Any] = {}
    for name in _field_names(type(message)):
        value = getattr(message, name)
        if isinstance(value, list):
            value = [to_dict(item) if dataclasses.is_dataclass(item) else item for item in value]
        elif dataclasses.is_dataclass(value):
            value = to_dict(value)
        out[name] = value
    return out


def decode(message_type: type[MessageT], payload: bytes | bytearray | memoryview) -> MessageT:
    """Parse JSON bytes into ``message_type``; malformed payloads raise InputError."""
    try:
        data = json.loads(bytes(payload))
        return from_dict(message_type, data)
    except (ValueError, TypeError, KeyError) as err:
        raise InputError(f"not a valid {message_type.__name__} message: {err}") from err


def from_dict(message_type: type[MessageT], data: dict[str, Any]) -> MessageT:
    """Build ``message_type`` from a field dict, nested dataclass lists included."""
    nested = _nested_list_fields(typing.cast(Any, message_type))
    if nested:
        data = dict(data)
        for name, item_type in nested.items():
            if name in data:
                data[name] = [from_dict(item_type, item) for item in data[name]]
    return message_type(**data)


def _field_names(message_type: type) -> tuple[str, ...]:
    names = _FIELD_NAMES.get(message_type)
    if names is None:
        names = _FIELD_NAMES[message_type] = tuple(f.name for f in dataclasses.fields(message_type))
    return names


_FIELD_NAMES: dict[type, tuple[str, ...]] = {}


@cache
def _nested_list_fields(message_type: Any) -> dict[str, type]:
    hints = typing.get_type_hints(message_type)
    found: dict[str, type] = {}
    for name, hint in hints.items():
        if typing.get_origin(hint) is list:
            (item,) = typing.get_args(hint)
            if isinstance(item, type) and dataclasses.is_dataclass(item):
                found[name] = item
    return found


def json_schema(message_type: type) -> dict[str, Any]:
    """JSON schema (draft 2020-12) of a message dataclass (computed once per type)."""
    cached = _SCHEMAS.get(message_type)
    if cached is not None:
        return cached
    schema = _object_schema(message_type)
    schema["$schema"] = "https://json-schema.org/draft/2020-12/schema"
    schema["title"] = f"boltwatch.{message_type.__name__}"
    doc = (message_type.__doc__ or "").strip().splitlines()
    if doc:
        schema["description"] = doc[0]
    _SCHEMAS[message_type] = schema
    return schema


_SCHEMAS: dict[type, dict[str, Any]] = {}


def _object_schema(message_type: type) -> dict[str, Any]:
    hints = typing.get_type_hints(message_type)
    properties = {f.name: _type_schema(hints[f.name]) for f in dataclasses.fields(message_type)}
    return {
        "type": "object",
        "properties": properties,
        "required": list(properties),
        "additionalProperties": False,
    }


def _type_schema(hint: Any) -> dict[str, Any]:
    origin = typing.get_origin(hint)
    if origin is typing.Literal:
        return {"type": "string", "enum": list(typing.get_args(hint))}
    if origin in (typing.Union, types.UnionType):
        options = [_type_schema(arg) for arg in typing.get_args(hint)]
        if all("type" in option and len(option) == 1 for option in options):
            return {"type": [option["type"] for option in options]}
        return {"anyOf": options}
    if origin is list:
        (item,) = typing.get_args(hint)
        return {"type": "array", "items": _type_schema(item)}
    if hint is type(None):
        return {"type": "null"}
    if dataclasses.is_dataclass(hint):
        return _object_schema(typing.cast(type, hint))
    if hint in _JSON_TYPES:
        return {"type": _JSON_TYPES[hint]}
    raise TypeError(f"no JSON schema for {hint!r}")
