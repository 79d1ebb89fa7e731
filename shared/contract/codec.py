"""JSON encoding of :mod:`shared.contract.messages` and the JSON schema of each type (pydantic).

The wire format is plain JSON (one object per message, UTF-8). pydantic's
``TypeAdapter`` of each message dataclass encodes it, validates what arrives
and writes its JSON schema, all from the dataclass annotations, so code,
decoder and schema cannot drift: every field's bounds
(:mod:`shared.contract.message_fields`) are checked and stated in the schema
(``minimum``/``maximum`` of integers, ``maxLength`` and ``pattern`` of
strings; numbers are finite unless the field says otherwise, which JSON
cannot say). A field with a default is not required (payloads from before it
was added stay valid and decode to the default); unknown fields, wrong types
and values out of bounds are refused. A payload is at most
:data:`MAX_PAYLOAD_BYTES`.

A payload pydantic refuses is looked at once more, field by field, by
:class:`~shared.contract.message_shape.MessageShape`: it takes what JSON Schema allows
and a strict parser does not (``1.0`` for an integer: producers such as
serde's f64 write it) and otherwise raises :class:`~shared.errors.InputError`
naming the field, its value and what was expected, as an operator reads it
in a log. Measured with ``tests/benchmarks/bench_codec.py`` (``docs/benchmarks.md``);
why pydantic: ``docs/explanation/decisions/0006-pydantic-codec.md``.
"""

from __future__ import annotations

import json
import typing
from collections.abc import Callable, Mapping
from typing import Any, TypeVar

from pydantic import TypeAdapter, ValidationError

from shared.contract.message_shape import MessageShape

MessageT = TypeVar("MessageT")

#: the largest payload decoded: 35 times the largest message any producer writes (a real
#: CS351 ControllerResult, 1.9 KB), so parsing one costs a receive thread well under a
#: millisecond; larger payloads are refused unread
MAX_PAYLOAD_BYTES = 64 * 1024


def _adapter(message_type: type[MessageT]) -> TypeAdapter[MessageT]:
    adapter = _ADAPTERS.get(message_type)
    if adapter is None:
        adapter = _ADAPTERS[message_type] = TypeAdapter(message_type)
    return adapter


_ADAPTERS: dict[type, TypeAdapter[Any]] = {}


def encode(message: Any) -> bytes:
    """The JSON bytes of one message (compact, UTF-8; a NaN a field allows is ``NaN``)."""
    return _adapter(type(message)).dump_json(message)


def to_dict(message: Any) -> dict[str, Any]:
    """The message's fields as a dict; nested messages (lists of them too) become dicts."""
    return typing.cast(dict[str, Any], _adapter(type(message)).dump_python(message))


def decode(message_type: type[MessageT], payload: bytes | bytearray | memoryview) -> MessageT:
    """Parse JSON bytes into ``message_type``, every field checked against its type and
    bounds (:mod:`shared.contract.message_fields`); what is refused raises InputError naming it."""
    decode_payload = _DECODERS.get(message_type)
    if decode_payload is None:
        decode_payload = _DECODERS[message_type] = decoder(message_type)
    return typing.cast(MessageT, decode_payload(bytes(payload)))


#: the decoder of each message type :func:`decode` was asked for
_DECODERS: dict[type, Callable[[bytes | bytearray], Any]] = {}


def decoder(
    message_type: type[MessageT], narrower: Mapping[str, tuple[float, float]] | None = None
) -> Callable[[bytes | bytearray], MessageT]:
    """The decoder of one message type; ``narrower``: tighter ranges for some integer
    fields (ids as wide as a station's CAN signals), checked after the type's own bounds.

    Missing fields take their defaults; unknown fields, wrong types, values
    out of bounds, payloads too large or nested too deeply and bad JSON
    raise InputError naming what is wrong.
    """
    validate = _adapter(message_type).validate_json
    shape = MessageShape(message_type, narrower)
    narrowed = tuple((name, low, high) for name, (low, high) in (narrower or {}).items())

    def decode_payload(payload: bytes | bytearray) -> MessageT:
        if len(payload) > MAX_PAYLOAD_BYTES:
            raise shape.error(f"{len(payload)} bytes, expected at most {MAX_PAYLOAD_BYTES}")
        try:
            message = validate(payload)
        except ValidationError:
            return _looked_at_closely(shape, payload)
        for name, low, high in narrowed:
            if not low <= getattr(message, name) <= high:
                return _looked_at_closely(shape, payload)
        return message

    return decode_payload


def _looked_at_closely(shape: MessageShape[MessageT], payload: bytes | bytearray) -> MessageT:
    """The message JSON Schema allows in ``payload``, or InputError naming what is wrong."""
    try:
        data = json.loads(payload)
    except RecursionError:
        raise shape.error("nested too deeply") from None
    except ValueError as err:
        raise shape.error(str(err)) from err
    return shape.from_data(data)


def json_schema(message_type: type) -> dict[str, Any]:
    """JSON schema (draft 2020-12) of a message dataclass, an object at its root (Foxglove
    and ``rerun mcap`` decode it); nested message types are ``$defs``."""
    schema = _SCHEMAS.get(message_type)
    if schema is None:
        schema = _without_titles(_adapter(message_type).json_schema())
        schema["$schema"] = "https://json-schema.org/draft/2020-12/schema"
        schema["title"] = f"boltwatch.{message_type.__name__}"
        doc = (message_type.__doc__ or "").strip().splitlines()
        if doc:
            schema["description"] = doc[0]
        _SCHEMAS[message_type] = schema
    return schema


_SCHEMAS: dict[type, dict[str, Any]] = {}


def _without_titles(schema: Any) -> Any:
    """pydantic's schema without the titles it makes of names ("Run Id"); a property
    named ``title`` (an object, not a string) stays."""
    if isinstance(schema, dict):
        return {
            key: _without_titles(value)
            for key, value in schema.items()
            if not (key == "title" and isinstance(value, str))
        }
    if isinstance(schema, list):
        return [_without_titles(item) for item in schema]
    return schema
