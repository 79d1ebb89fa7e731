"""What a decoder derives once from a message type: its fields, their JSON types and bounds.

:class:`MessageShape` holds, per field, the Python types ``json.loads`` may
give for it, its enum values, its bounds (:mod:`shared.contract.message_fields`) and,
for a nested message (or a list of them), its shape. :meth:`~MessageShape.checked`
checks a list of field values field by field, converts what JSON Schema
allows (``1.0`` for an integer, ``1`` for a number) and raises
:class:`~shared.errors.InputError` naming the first field that is wrong;
:mod:`shared.contract.codec` calls it for a payload its validator (pydantic) refused, to take
what JSON Schema allows and to say what is wrong in an operator's words.
"""

from __future__ import annotations

import dataclasses
import types
import typing
from collections.abc import Mapping
from typing import Any, Generic, TypeVar

from shared.contract.message_fields import (
    DEFAULT_FLOAT,
    DEFAULT_INT,
    DEFAULT_TEXT,
    NumberRange,
    TextRange,
)
from shared.errors import InputError

MessageT = TypeVar("MessageT")

#: the longest value quoted in an error (a refused payload may hold 64 KiB of text)
QUOTED_CHARS = 60

JSON_NAMES: dict[type, str] = {
    int: "integer",
    float: "number",
    str: "string",
    bool: "boolean",
    type(None): "null",
    list: "array",
    dict: "object",
}


def cut(text: str) -> str:
    """``text``, cut to :data:`QUOTED_CHARS` characters."""
    return text if len(text) <= QUOTED_CHARS else f"{text[:QUOTED_CHARS]}... ({len(text)} chars)"


def quoted(value: Any) -> str:
    """``repr(value)``, cut to :data:`QUOTED_CHARS` characters."""
    if isinstance(value, int) and not isinstance(value, bool) and value.bit_length() > 128:
        return f"an integer of {len(str(value))} digits"
    return cut(repr(value))


class MessageShape(Generic[MessageT]):
    """The fields of one message type and what each may hold (``narrower``: tighter ranges)."""

    def __init__(
        self,
        message_type: type[MessageT],
        narrower: Mapping[str, tuple[float, float]] | None = None,
    ) -> None:
        hints = typing.get_type_hints(message_type, include_extras=True)
        fields = dataclasses.fields(typing.cast(Any, message_type))
        self.message_type = message_type
        self.type_name = message_type.__name__
        self.names = tuple(f.name for f in fields)
        self.defaults: dict[str, Any] = {
            f.name: f.default for f in fields if f.default is not dataclasses.MISSING
        }
        self.factories = {
            f.name: f.default_factory
            for f in fields
            if f.default_factory is not dataclasses.MISSING
        }
        narrower = narrower or {}
        unknown = set(narrower) - set(self.names)
        if unknown:
            raise TypeError(f"{self.type_name} has no field(s) {', '.join(sorted(unknown))}")
        self.allowed: list[frozenset[type]] = []
        self.numbers: dict[int, NumberRange] = {}
        self.texts: dict[int, TextRange] = {}
        self.enums: dict[int, frozenset[Any]] = {}
        self.nested: dict[int, MessageShape[Any]] = {}  # a list of nested messages
        self.nested_one: dict[int, MessageShape[Any]] = {}  # one nested message
        for index, name in enumerate(self.names):
            self._derive(index, hints[name], narrower.get(name))

    def _derive(self, index: int, hint: Any, narrower: tuple[float, float] | None) -> None:
        options = _options(hint)
        allowed: set[type] = set()
        for base, bound in options:
            origin = typing.get_origin(base)
            if origin is typing.Literal:
                values = typing.get_args(base)
                allowed.update(type(value) for value in values)
                self.enums[index] = self.enums.get(index, frozenset()) | frozenset(values)
            elif origin is list or dataclasses.is_dataclass(base):
                allowed.add(self._derive_nested(index, base))
            elif base is type(None):
                allowed.add(type(None))
            elif base in (int, float):
                allowed.update((int, float) if base is float else (int,))
                default = DEFAULT_FLOAT if base is float else DEFAULT_INT
                number = bound if isinstance(bound, NumberRange) else default
                if narrower is not None:
                    number = NumberRange(
                        max(number.low, narrower[0]), min(number.high, narrower[1]), number.nan_ok
                    )
                self.numbers[index] = number
            elif base is str:
                allowed.add(str)
                self.texts[index] = bound if isinstance(bound, TextRange) else DEFAULT_TEXT
            elif base is bool:
                allowed.add(bool)
            else:
                raise TypeError(f"no decoder for a field of type {base!r}")
        if index in self.enums:  # an enum's values are its bounds
            self.texts.pop(index, None)
            if type(None) in allowed:
                self.enums[index] |= {None}
        self.allowed.append(frozenset(allowed))

    def _derive_nested(self, index: int, base: Any) -> type:
        """A list of nested messages (its JSON type: list) or one nested message (dict)."""
        if typing.get_origin(base) is list:
            (item,) = typing.get_args(base)
            if not dataclasses.is_dataclass(item):
                raise TypeError(f"no decoder for a list of {item!r}")
            self.nested[index] = MessageShape(typing.cast(type, item))
            return list
        self.nested_one[index] = MessageShape(typing.cast(type, base))
        return dict

    def error(self, text: str) -> InputError:
        return InputError(f"not a valid {self.type_name} message: {text}")

    def from_data(self, data: Any) -> MessageT:
        """The message of a parsed JSON value; InputError naming what is wrong."""
        return self.message_type(*self.checked(self.values_of(data)))

    def values_of(self, data: Any) -> list[Any]:
        """The field values of ``data`` with defaults filled in; InputError if it cannot be."""
        if not isinstance(data, dict):
            raise self.error("not a JSON object")
        unknown = sorted(set(data) - set(self.names))
        if unknown:
            more = f" and {len(unknown) - 5} more" if len(unknown) > 5 else ""
            raise self.error(f"unknown field(s) {cut(', '.join(unknown[:5]))}{more}")
        missing = [
            n for n in self.names if n not in data and n not in self.defaults | self.factories
        ]
        if missing:
            raise self.error(f"missing field(s) {', '.join(missing)}")
        return [self._value_or_default(data, name) for name in self.names]

    def _value_or_default(self, data: dict[str, Any], name: str) -> Any:
        if name in data:
            return data[name]
        if name in self.defaults:
            return self.defaults[name]
        return self.factories[name]()

    def checked(self, values: list[Any]) -> list[Any]:
        """``values`` checked field by field, converted where JSON Schema allows."""
        out = []
        for index, value in enumerate(values):
            out.append(self._checked(index, value))
        return out

    def _checked(self, index: int, value: Any) -> Any:
        value = self._converted(index, value)
        if value is None:
            return value
        self._check_enum_and_number(index, value)
        text = self.texts.get(index)
        if text is not None and type(value) is str:
            self._check_text(index, value, text)
        one_shape = self.nested_one.get(index)
        if one_shape is not None:
            try:
                return one_shape.from_data(value)
            except InputError as err:
                raise self.error(f"{self.names[index]}: {err}") from None
        item_shape = self.nested.get(index)
        if item_shape is not None:
            try:
                return [item_shape.from_data(item) for item in value]
            except InputError as err:
                raise self.error(f"{self.names[index]}: {err}") from None
        return value

    def _converted(self, index: int, value: Any) -> Any:
        """``value`` as its field's type where JSON Schema allows; InputError when not allowed."""
        allowed = self.allowed[index]
        kind = type(value)
        if kind is float and int in allowed and float not in allowed and value.is_integer():
            value, kind = int(value), int  # ``1.0`` is a JSON Schema integer
        elif kind is int and float in allowed:
            try:
                value, kind = float(value), float
            except OverflowError:
                raise self.error(
                    f"{self.names[index]} is {quoted(value)}, beyond any number"
                ) from None
        if kind not in allowed:
            expected = " or ".join(sorted(JSON_NAMES[t] for t in allowed))
            raise self.error(
                f"{self.names[index]} is {JSON_NAMES.get(kind, kind.__name__)} "
                f"{quoted(value)}, expected {expected}"
            )
        return value

    def _check_enum_and_number(self, index: int, value: Any) -> None:
        enum = self.enums.get(index)
        if enum is not None and value not in enum:
            expected = ", ".join(sorted(repr(v) for v in enum if v is not None))
            raise self.error(f"{self.names[index]} is {quoted(value)}, expected one of {expected}")
        number = self.numbers.get(index)
        if (
            number is not None
            and type(value) in (int, float)
            and not number.low <= value <= number.high
            and not (number.nan_ok and type(value) is float)
        ):
            expected = (
                "a finite number"
                if (number.low, number.high) == (DEFAULT_FLOAT.low, DEFAULT_FLOAT.high)
                else f"{_number_text(number.low)} to {_number_text(number.high)}"
            )
            raise self.error(f"{self.names[index]} is {quoted(value)}, expected {expected}")

    def _check_text(self, index: int, value: str, text: TextRange) -> None:
        if len(value) > text.max_chars:
            raise self.error(
                f"{self.names[index]} has {len(value)} characters, "
                f"expected at most {text.max_chars}"
            )
        if text.pattern is not None and text.pattern.fullmatch(value) is None:
            raise self.error(
                f"{self.names[index]} is {quoted(value)}, expected {text.pattern.pattern}"
            )


def _options(hint: Any) -> list[tuple[Any, Any]]:
    """(base type, its bound or None) of each alternative of a field's annotation."""
    origin = typing.get_origin(hint)
    if origin in (typing.Union, types.UnionType):
        return [option for arg in typing.get_args(hint) for option in _options(arg)]
    if origin is typing.Annotated:
        base, *extras = typing.get_args(hint)
        bound = next((e for e in extras if isinstance(e, NumberRange | TextRange)), None)
        return [(base, bound)]
    return [(hint, None)]


def _number_text(value: float) -> str:
    if isinstance(value, int) and abs(value) >= 2**62:
        return f"{'-' if value < 0 else ''}2**{(abs(value) + 1).bit_length() - 1}" + (
            " - 1" if value > 0 else ""
        )
    return f"{value:g}" if isinstance(value, float) else str(value)
