"""An event as the server serves it: its types and its fields by browse path, pure (asyncua's
``ua`` types, no server).

A :class:`ServedEvent` holds what a client may select (OPC 10000-4, 7.22.3): each field
by its browse path from the event type (``Message``, ``Result``,
``JoiningSystemEventContent/EventCode``, ``AckedState/Id``), each name with its
namespace index; the event's type and its supertypes (``OfType`` and a select clause's
``TypeDefinitionId`` are answered from them); a condition's ``ConditionId`` (the
``NodeId`` attribute of its event, OPC 10000-9, 5.5.2).

:meth:`ServedEvent.value` answers a browse path. A path that goes on past a field whose
value is a structure goes into it by the names of its fields (their namespaces are not
looked at: a structure's fields have names, not browse names), so a client selects
``Result/ResultMetaData/ResultId`` of a result-ready event and receives the ResultId,
typed as its structure declares it. A path to nothing gives None (a null field).
"""

from __future__ import annotations

import dataclasses
import functools
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from enum import Enum
from typing import Any, cast

from asyncua import ua
from asyncua.ua.ua_binary import get_safe_type_hints, resolve_uatype
from asyncua.ua.uatypes import type_from_list, type_is_list

#: one name of a browse path: (namespace index, name)
PathName = tuple[int, str]
FieldPath = tuple[PathName, ...]


def field_path(*names: PathName | str) -> FieldPath:
    """A path of ``(namespace, name)`` pairs; a bare string is a name of namespace 0."""
    return tuple((0, name) if isinstance(name, str) else name for name in names)


@dataclass(frozen=True, slots=True)
class ServedEvent:
    """One event: its type first in ``types``, then its supertypes up to BaseEventType."""

    types: tuple[ua.NodeId, ...]
    fields: Mapping[FieldPath, ua.Variant]
    #: the NodeId of the condition whose state this event reports (None: not a condition)
    condition_id: ua.NodeId | None = None
    #: what the event is reported for (ConditionRefresh: the notifiers that see it)
    notifiers: tuple[ua.NodeId, ...] = field(default=())

    @property
    def event_type(self) -> ua.NodeId:
        return self.types[0]

    def is_of_type(self, type_id: ua.NodeId) -> bool:
        """The event is of ``type_id`` or of one of its subtypes."""
        return type_id in self.types

    def value(self, path: Sequence[ua.QualifiedName]) -> ua.Variant | None:
        """The field at ``path``, into a structure's fields past a field; None: no such field."""
        names = tuple((int(name.NamespaceIndex), str(name.Name)) for name in path)
        for length in range(len(names), 0, -1):
            found = self.fields.get(names[:length])
            if found is not None:
                return structure_field(found, [name for _ns, name in names[length:]])
        return None


def structure_field(variant: ua.Variant, names: Sequence[str]) -> ua.Variant | None:
    """The field ``names`` of the structure in ``variant`` (itself when ``names`` is empty),
    as a variant of the type its structure declares; None when there is no such field or
    a structure on the way is null."""
    value: Any = variant.Value
    kind: tuple[ua.VariantType | None, bool] = (variant.VariantType, bool(variant.is_array))
    for name in names:
        if value is None or isinstance(value, list) or not dataclasses.is_dataclass(value):
            return None
        hints = _field_types(cast(type, type(value)))
        if name not in hints:
            return None
        value = getattr(value, name)
        if isinstance(value, ua.Variant):  # a field of type BaseDataType: its own variant
            value, kind = value.Value, (value.VariantType, bool(value.is_array))
        else:
            kind = hints[name]
    if value is None:
        return ua.Variant()
    variant_type, is_array = kind
    if variant_type is None:
        return ua.Variant(value)  # a type asyncua's hints do not say: as asyncua guesses it
    return ua.Variant(value, variant_type, is_array=is_array)


@functools.cache
def _field_types(cls: type) -> dict[str, tuple[ua.VariantType | None, bool]]:
    """Each field of a structure's class and the variant type of its values (and whether an
    array), from the class's type hints as asyncua's encoder resolves them."""
    hints = get_safe_type_hints(cls, {"ua": ua})
    found = {}
    for item in dataclasses.fields(cls):
        if item.name not in hints:
            continue
        hint, _optional = resolve_uatype(hints[item.name])
        is_array = type_is_list(hint)
        if is_array:
            hint, _optional = resolve_uatype(type_from_list(hint))
        found[item.name] = (variant_type_of(hint), is_array)
    return found


def variant_type_of(hint: Any) -> ua.VariantType | None:
    """The variant type of values of an asyncua type (an alias such as UtcTime is its base
    type's class: DateTime; an enumeration is Int32; a structure an ExtensionObject); None
    for another."""
    if isinstance(hint, type):
        if issubclass(hint, Enum):
            return ua.VariantType.Int32
        if hint.__name__ in ua.VariantType.__members__:
            return ua.VariantType[hint.__name__]
        if issubclass(hint, ua.NodeId):
            return ua.VariantType.NodeId
        if dataclasses.is_dataclass(hint):
            return ua.VariantType.ExtensionObject
    return None
