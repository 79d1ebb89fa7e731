"""JSON encoding of :mod:`shared.messages` and the JSON schema of each type.

The wire format is plain JSON (one object per message, UTF-8). The schema is
derived from the dataclass annotations, so code and schema cannot drift:
``int`` -> integer, ``float`` -> number, ``str`` -> string, ``X | None`` ->
``[X, null]``, ``Literal[...]`` -> enum, nested dataclasses and lists nest.
A field with a default is not required (payloads from before it was added
stay valid and decode to the default). Every field's bounds
(:mod:`shared.message_fields`) are checked by the decoders and stated in
the schema (``minimum``/``maximum`` of integers, ``maxLength`` and
``pattern`` of strings; numbers are finite, which JSON cannot say
otherwise). A payload is at most :data:`MAX_PAYLOAD_BYTES`; one nested more
deeply than Python's JSON parser can follow is refused, and one nested more
than its schema is a wrong type.
"""

from __future__ import annotations

import dataclasses
import json
import types
import typing
from collections.abc import Callable, Mapping
from functools import cache
from typing import Any, TypeVar

from shared.message_fields import DEFAULT_INT, DEFAULT_TEXT, NumberRange, TextRange
from shared.message_shape import MessageShape

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


#: the largest payload decoded: 35 times the largest message any producer writes (a real
#: CS351 ControllerResult, 1.9 KB), so parsing one costs a receive thread well under a
#: millisecond; larger payloads are refused unread
MAX_PAYLOAD_BYTES = 64 * 1024


def decode(message_type: type[MessageT], payload: bytes | bytearray | memoryview) -> MessageT:
    """Parse JSON bytes into ``message_type``, every field checked against its type and
    bounds (:mod:`shared.message_fields`); what is refused raises InputError naming it."""
    decode_payload = _DECODERS.get(message_type)
    if decode_payload is None:
        decode_payload = _DECODERS[message_type] = _general_decoder(message_type)
    return typing.cast(MessageT, decode_payload(bytes(payload)))


#: the decoder of each message type :func:`decode` was asked for
_DECODERS: dict[type, Callable[[bytes], Any]] = {}


def _general_decoder(message_type: type[MessageT]) -> Callable[[bytes], MessageT]:
    shape = MessageShape(message_type)
    if shape.is_flat:
        return decoder(message_type)

    def decode_nested(payload: bytes) -> MessageT:
        return shape.from_data(_parse(shape, payload))

    return decode_nested


def _parse(shape: MessageShape[Any], payload: bytes | bytearray) -> Any:
    """The JSON value of ``payload``; InputError when too large, too deep or not JSON."""
    if len(payload) > MAX_PAYLOAD_BYTES:
        raise shape.error(f"{len(payload)} bytes, expected at most {MAX_PAYLOAD_BYTES}")
    try:
        return _loads_utf8(payload)
    except RecursionError:
        raise shape.error("nested too deeply") from None
    except ValueError as err:
        raise shape.error(str(err)) from err


def decoder(
    message_type: type[MessageT], narrower: Mapping[str, tuple[float, float]] | None = None
) -> Callable[[bytes | bytearray], MessageT]:
    """A checking decoder of one flat message type, for the hot paths (samples at 1 kHz).

    It checks the payload's size, every field's JSON type against the schema
    (integer, number, string, enum, null) and every field's bounds
    (:mod:`shared.message_fields`; ``narrower``: tighter ranges for some
    fields, e.g. ids as wide as a station's CAN signals), and it is fast:
    fields are looked up and checked with C-level ``map`` calls, the
    dataclass is built positionally; anything the fast checks do not pass is
    checked again field by field (:meth:`MessageShape.checked`), which
    converts what JSON Schema allows and names the field it refuses.
    Missing fields take their defaults; unknown fields, wrong types, values
    out of bounds, payloads too large or nested too deeply and bad JSON
    raise InputError. Types with nested dataclasses or lists are refused
    (use :func:`decode`).
    """
    shape = MessageShape(message_type, narrower)
    if not shape.is_flat:
        raise TypeError(f"codec.decoder handles flat messages only, not {shape.type_name}")
    names, build, field_count = shape.names, shape.message_type, len(shape.names)
    fast_check, checked = shape.fast_check(), shape.checked

    def decode_flat(payload: bytes | bytearray) -> MessageT:
        if len(payload) > MAX_PAYLOAD_BYTES:
            raise shape.error(f"{len(payload)} bytes, expected at most {MAX_PAYLOAD_BYTES}")
        try:
            data = _loads_utf8(payload)
            if type(data) is not dict or len(data) != field_count:
                raise KeyError  # the slow path names what is wrong
            values = list(map(data.__getitem__, names))
        except RecursionError:
            raise shape.error("nested too deeply") from None
        except (ValueError, TypeError) as err:
            raise shape.error(str(err)) from err
        except KeyError:  # a field missing (perhaps with a default) or unknown
            values = shape.values_of(data)
        try:
            passed = fast_check(*values)
        except TypeError:  # an unhashable value where an enum or a station id goes
            passed = False
        if not passed:
            values = checked(values)
            shape.remember_matches(values)
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


def _field_names(message_type: type) -> tuple[str, ...]:
    names = _FIELD_NAMES.get(message_type)
    if names is None:
        names = _FIELD_NAMES[message_type] = tuple(f.name for f in dataclasses.fields(message_type))
    return names


_FIELD_NAMES: dict[type, tuple[str, ...]] = {}


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
    hints = typing.get_type_hints(message_type, include_extras=True)
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


#: keywords that only constrain one JSON type: options of a union may share one object
_TYPE_KEYWORDS = frozenset({"type", "minimum", "maximum", "maxLength", "pattern"})


def _type_schema(hint: Any) -> dict[str, Any]:
    origin = typing.get_origin(hint)
    if origin is typing.Annotated:
        base, *extras = typing.get_args(hint)
        schema = _type_schema(base)
        for extra in extras:
            schema.update(_bound_keywords(extra))
        return schema
    if origin is typing.Literal:
        return {"type": "string", "enum": list(typing.get_args(hint))}
    if origin in (typing.Union, types.UnionType):
        options = [_type_schema(arg) for arg in typing.get_args(hint)]
        bounded = [option for option in options if len(option) > 1]
        if all(set(option) <= _TYPE_KEYWORDS for option in options) and len(bounded) <= 1:
            merged = {"type": [option["type"] for option in options]}
            merged.update({k: v for option in bounded for k, v in option.items() if k != "type"})
            return merged
        return {"anyOf": options}
    if origin is list:
        (item,) = typing.get_args(hint)
        return {"type": "array", "items": _type_schema(item)}
    if hint is type(None):
        return {"type": "null"}
    if dataclasses.is_dataclass(hint):
        return _object_schema(typing.cast(type, hint))
    if hint is int:  # a field with no bound of its own: what 64 signed bits hold
        return {"type": "integer", "minimum": DEFAULT_INT.low, "maximum": DEFAULT_INT.high}
    if hint is str:
        return {"type": "string", "maxLength": DEFAULT_TEXT.max_chars}
    if hint in _JSON_TYPES:
        return {"type": _JSON_TYPES[hint]}
    raise TypeError(f"no JSON schema for {hint!r}")


def _bound_keywords(bound: Any) -> dict[str, Any]:
    """JSON Schema keywords of a field bound (a number's finiteness has none: JSON has no NaN)."""
    if isinstance(bound, NumberRange) and isinstance(bound.low, int):
        return {"minimum": bound.low, "maximum": bound.high}
    if isinstance(bound, TextRange):
        keywords: dict[str, Any] = {"maxLength": bound.max_chars}
        if bound.pattern is not None:
            keywords["pattern"] = f"^{bound.pattern.pattern}$"
        return keywords
    return {}
