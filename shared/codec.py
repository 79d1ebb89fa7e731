"""JSON encoding of :mod:`shared.messages` and the JSON schema of each type.

The wire format is plain JSON (one object per message, UTF-8). The schema is
derived from the dataclass annotations, so code and schema cannot drift:
``int`` -> integer, ``float`` -> number, ``str`` -> string, ``X | None`` ->
``[X, null]``, ``Literal[...]`` -> enum, nested dataclasses and lists nest.
A field with a default is not required (payloads from before it was added
stay valid and decode to the default).
"""

from __future__ import annotations

import dataclasses
import json
import types
import typing
from collections.abc import Callable
from functools import cache
from typing import Any, TypeVar

from shared.errors import InputError

MessageT = TypeVar("MessageT")

_JSON_TYPES: dict[type, str] = {int: "integer", float: "number", str: "string", bool: "boolean"}


#: ``json.dumps(..., separators=(",", ":"))`` without building an encoder per call
_COMPACT = json.JSONEncoder(separators=(",", ":"))


def encode(message: Any) -> bytes:
    """The JSON bytes of one message (compact, UTF-8)."""
    return _COMPACT.encode(to_dict(message)).encode()


def to_dict(message: Any) -> dict[str, Any]:
    """Shallow field dict; nested dataclasses (lists of them too) become dicts.

    Only fields whose annotation can hold a list or a dataclass are looked at
    twice (the predictor publishes an event and an intensity per stick-slip).
    """
    names, nested = _encoding_plan(typing.cast(Any, type(message)))
    out = {name: getattr(message, name) for name in names}
    for name in nested:
        value = out[name]
        if isinstance(value, list):
            out[name] = [
                to_dict(item) if dataclasses.is_dataclass(item) else item for item in value
            ]
        elif dataclasses.is_dataclass(value):
            out[name] = to_dict(value)
    return out


@cache
def _encoding_plan(message_type: Any) -> tuple[tuple[str, ...], tuple[str, ...]]:
    """(every field name, the names of fields that may hold a list or a dataclass)."""
    hints = typing.get_type_hints(message_type)
    names = _field_names(message_type)
    return names, tuple(name for name in names if _may_nest(hints.get(name, Any)))


def _may_nest(hint: Any) -> bool:
    if hint is Any or typing.get_origin(hint) is list or dataclasses.is_dataclass(hint):
        return True
    return any(_may_nest(arg) for arg in typing.get_args(hint))


def decode(message_type: type[MessageT], payload: bytes | bytearray | memoryview) -> MessageT:
    """Parse JSON bytes into ``message_type``; malformed payloads raise InputError."""
    try:
        data = json.loads(bytes(payload))
        return from_dict(message_type, data)
    except (ValueError, TypeError, KeyError) as err:
        raise InputError(f"not a valid {message_type.__name__} message: {err}") from err


def decoder(message_type: type[MessageT]) -> Callable[[bytes | bytearray], MessageT]:
    """A checking decoder of one flat message type, for the hot paths (samples at 1 kHz).

    Unlike :func:`decode`, it checks every field's JSON type against the
    schema (integer, number, string, enum, null), and it is about as fast:
    fields are looked up and checked with C-level ``map`` calls, the
    dataclass is built positionally. Missing fields take their defaults;
    unknown fields, wrong types and bad JSON raise InputError naming the field.
    Types with nested dataclasses or lists are refused (use :func:`decode`).
    """
    flat = _FlatMessage(message_type)
    names, allowed, enums, build = flat.names, flat.allowed, flat.enums, flat.message_type
    loads, contains, field_count = _loads_utf8, frozenset.__contains__, len(flat.names)

    def decode_flat(payload: bytes | bytearray) -> MessageT:
        try:
            data = loads(payload)
            if type(data) is not dict or len(data) != field_count:
                raise KeyError  # the slow path names what is wrong
            values = list(map(data.__getitem__, names))
        except (ValueError, TypeError) as err:
            raise InputError(f"not a valid {flat.type_name} message: {err}") from err
        except KeyError:  # a field missing (perhaps with a default) or unknown
            values = flat.with_defaults(data)
        if not all(map(contains, allowed, map(type, values))):
            values = flat.integral_floats_as_ints(values)
            if not all(map(contains, allowed, map(type, values))):
                raise InputError(flat.type_error(values))
        for index, enum in enums:
            if values[index] not in enum:
                raise InputError(flat.enum_error(index, values[index]))
        return build(*values)

    return decode_flat


_DECODER = json.JSONDecoder()


def _loads_utf8(payload: bytes | bytearray) -> Any:
    """``json.loads(payload)``, in half the time for the usual compact UTF-8 object.

    ``json.loads`` on bytes first sniffs the encoding and wraps the C scanner
    in two Python calls; ``raw_decode`` of a decoded str skips both. Anything
    unusual (another encoding, surrounding whitespace, trailing data, an
    error) goes to ``json.loads`` itself, so results and errors are its own.
    """
    try:
        text = payload.decode()
        value, end = _DECODER.raw_decode(text)
        if end == len(text):
            return value
    except ValueError:  # UnicodeDecodeError and JSONDecodeError included
        pass
    return json.loads(payload)


class _FlatMessage(typing.Generic[MessageT]):
    """What :func:`decoder` derives once from a flat message type, and its error texts."""

    def __init__(self, message_type: type[MessageT]) -> None:
        hints = typing.get_type_hints(message_type)
        fields = dataclasses.fields(typing.cast(Any, message_type))
        self.message_type = message_type
        self.type_name = message_type.__name__
        self.names = tuple(f.name for f in fields)
        self.defaults = {f.name: f.default for f in fields if f.default is not dataclasses.MISSING}
        self.allowed = tuple(_json_python_types(hints[name]) for name in self.names)
        self.enums = tuple(
            (index, values)
            for index, name in enumerate(self.names)
            if (values := _enum_values(hints[name])) is not None
        )

    def with_defaults(self, data: Any) -> list[Any]:
        """The field values of ``data`` with defaults filled in; InputError if it cannot be."""
        name = self.type_name
        if not isinstance(data, dict):
            raise InputError(f"not a valid {name} message: not a JSON object")
        unknown = sorted(set(data) - set(self.names))
        if unknown:
            raise InputError(f"not a valid {name} message: unknown field(s) {', '.join(unknown)}")
        missing = [n for n in self.names if n not in data and n not in self.defaults]
        if missing:
            raise InputError(f"not a valid {name} message: missing field(s) {', '.join(missing)}")
        return [data[n] if n in data else self.defaults[n] for n in self.names]

    def integral_floats_as_ints(self, values: list[Any]) -> list[Any]:
        """``1.0`` where an integer is expected is a JSON Schema integer: make it ``1``."""
        return [
            int(value)
            if type(value) is float
            and float not in allowed
            and int in allowed
            and value.is_integer()
            else value
            for value, allowed in zip(values, self.allowed, strict=True)
        ]

    def type_error(self, values: list[Any]) -> str:
        for field_name, value, allowed in zip(self.names, values, self.allowed, strict=True):
            if type(value) not in allowed:
                expected = " or ".join(sorted(_JSON_NAMES[t] for t in allowed))
                return (
                    f"not a valid {self.type_name} message: {field_name} is "
                    f"{_JSON_NAMES.get(type(value), type(value).__name__)} {value!r}, "
                    f"expected {expected}"
                )
        return f"not a valid {self.type_name} message"  # pragma: no cover

    def enum_error(self, index: int, value: Any) -> str:
        enum = next(values for i, values in self.enums if i == index)
        return (
            f"not a valid {self.type_name} message: {self.names[index]} is {value!r}, "
            f"expected one of {', '.join(sorted(map(repr, enum)))}"
        )


_JSON_NAMES: dict[type, str] = {
    int: "integer",
    float: "number",
    str: "string",
    bool: "boolean",
    type(None): "null",
    list: "array",
    dict: "object",
}


def _json_python_types(hint: Any) -> frozenset[type]:
    """The Python types ``json.loads`` gives for a value the field's schema allows."""
    origin = typing.get_origin(hint)
    if origin is typing.Literal:
        return frozenset(type(value) for value in typing.get_args(hint))
    if origin in (typing.Union, types.UnionType):
        return frozenset().union(*(_json_python_types(arg) for arg in typing.get_args(hint)))
    if hint is type(None):
        return frozenset({type(None)})
    if hint is float:  # a JSON number may be written without a fraction
        return frozenset({float, int})
    if hint in (int, str, bool):
        return frozenset({hint})
    raise TypeError(f"codec.decoder handles flat messages only, not a field of type {hint!r}")


def _enum_values(hint: Any) -> frozenset[Any] | None:
    """The allowed values of a ``Literal`` field (``None`` too when optional), else None."""
    origin = typing.get_origin(hint)
    if origin is typing.Literal:
        return frozenset(typing.get_args(hint))
    if origin in (typing.Union, types.UnionType):
        parts = [_enum_values(arg) for arg in typing.get_args(hint)]
        if any(part is not None for part in parts):
            allowed: set[Any] = set()
            for arg, part in zip(typing.get_args(hint), parts, strict=True):
                allowed |= part if part is not None else {None} if arg is type(None) else set()
            return frozenset(allowed)
    return None


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
    """Every field a property; required unless it has a default (a field added later with a
    default keeps older payloads, which lack it, valid: they decode to the default)."""
    hints = typing.get_type_hints(message_type)
    fields = dataclasses.fields(message_type)
    properties = {f.name: _type_schema(hints[f.name]) for f in fields}
    return {
        "type": "object",
        "properties": properties,
        "required": [f.name for f in fields if _required(f)],
        "additionalProperties": False,
    }


def _required(field: dataclasses.Field[Any]) -> bool:
    return field.default is dataclasses.MISSING and field.default_factory is dataclasses.MISSING


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
