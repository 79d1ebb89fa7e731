"""The seven NodeSet2 files into an asyncua server, and what asyncua 2.1 needs for them.

:func:`load_models` imports :data:`~.nodeset_files.NODESET_FILES` in order, then
generates the Python classes of their structures (``ua.JoiningResultDataType``
and kin). asyncua 2.1 reads the official files with four gaps, each handled
here and nowhere else, none by writing a part of the model by hand:

1. **DI, strict mode off.** Nine objects of DI (``ns=DI;i=73..75, 90..95``:
   Configuration, Tuning, Maintenance, Diagnostics, Statistics, Status,
   Operational, OperationCounters, Identification) are ``DesignToolOnly`` browse
   name definitions with no parent at all. asyncua adds them below the null node
   (``i=0``), which no address space has: ``BadParentNodeIdInvalid``. They are
   for design tools, not servers; DI is imported with ``strict_mode=False`` and
   these nine, and only they, are left out (:data:`DI_DESIGN_TOOL_ONLY`; any other
   failure there is an error).
2. **Default values holding a structure in a structure.** The default value of
   ``ResultType`` (Machinery/Result), ``JoiningSystemResultType`` and of the
   ``Result`` of ``JoiningSystemResultReadyEventType`` (IJT Base), and a few
   placeholders, is an empty ``ResultDataType`` whose ``ResultMetaData`` is an
   ExtensionObject inside the structure's body; asyncua's XML reader fails on it
   (``KeyError: 'TypeId'``) and the node is lost, the event type's ``Result``
   with it. These default values (empty results) are dropped before the import
   (:func:`readable_nodeset`); the nodes come in without them.
3. **Inherited fields.** A NodeSet2 ``<Definition>`` lists a structure's own
   fields; the DataTypeDefinition a server gives includes the supertype's first
   (OPC 10000-3, StructureDefinition; node-opcua's client reads it so).
   asyncua takes the file's list as it is, so ``JoiningResultMetaDataType`` would
   lack ``ResultId``, ``CreationTime``, ``PartId``... :func:`complete_structures`
   puts the supertype's fields first, in the address space.
4. **Fields that allow subtypes.** ``ResultDataType.ResultMetaData`` has
   ``AllowSubTypes="true"``: a ``StructureWithSubtypedValues`` whose field is
   encoded as an ExtensionObject (so a ``JoiningResultMetaDataType`` fits in it).
   asyncua's reader drops the attribute. The address space gets the structure
   type the model says, and the Python class of such a structure is generated with
   those fields as ExtensionObjects (:func:`generate_classes`).
"""

from __future__ import annotations

import logging
import time
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, cast

from asyncua import Server, ua
from asyncua.common.structures104 import load_data_type_definitions, make_structure

from services.opcua.nodeset_files import FETCH_COMMAND, NODESET_FILES, missing_files
from shared.errors import ConfigError

LOG = logging.getLogger(__name__)

UA_NODESET = "{http://opcfoundation.org/UA/2011/03/UANodeSet.xsd}"
DI_FILE = "Opc.Ua.Di.NodeSet2.xml"
#: DI's DesignToolOnly objects without a parent (numeric ids in DI's namespace)
DI_DESIGN_TOOL_ONLY = frozenset({73, 74, 75, 90, 91, 92, 93, 94, 95})
#: the namespaces the server needs, by model URI
IJT_BASE = "http://opcfoundation.org/UA/IJT/Base/"
MACHINERY = "http://opcfoundation.org/UA/Machinery/"
MACHINERY_RESULT = "http://opcfoundation.org/UA/Machinery/Result/"
MODEL_URIS = (
    "http://opcfoundation.org/UA/DI/",
    "http://opcfoundation.org/UA/IA/",
    MACHINERY,
    MACHINERY_RESULT,
    "http://opcfoundation.org/UA/AMB/",
    IJT_BASE,
    "http://opcfoundation.org/UA/IJT/Tightening/",
)


def node_id(identifier: int | str, namespace: int = 0) -> ua.NodeId:
    """``ua.NodeId`` of plain values (asyncua types its arguments as its own NewTypes)."""
    return ua.NodeId(cast(Any, identifier), cast(Any, namespace))


class ModelLoadError(ConfigError):
    """The models cannot be loaded (files missing, a node the server needs refused)."""


@dataclass
class ReadableNodeset:
    """One file as asyncua can read it, and what was taken out or noted on the way."""

    text: str
    dropped_values: list[str] = field(default_factory=list)  # NodeIds (the file's own)
    #: structure name -> its fields that allow subtypes (``AllowSubTypes="true"``)
    subtyped_fields: dict[str, set[str]] = field(default_factory=dict)


def readable_nodeset(path: Path) -> ReadableNodeset:
    """The file without the default values asyncua cannot read (gap 2), with the fields
    that allow subtypes noted (gap 4)."""
    root = ET.parse(path).getroot()
    found = ReadableNodeset("")
    for node in root:
        definition = node.find(UA_NODESET + "Definition")
        if definition is not None:
            subtyped = {
                str(item.get("Name"))
                for item in definition.findall(UA_NODESET + "Field")
                if item.get("AllowSubTypes") == "true"
            }
            if subtyped:
                name = str(node.get("BrowseName")).split(":", 1)[-1]
                found.subtyped_fields[name] = subtyped
        value = node.find(UA_NODESET + "Value")
        if value is not None and _holds_nested_structure(value):
            node.remove(value)
            found.dropped_values.append(str(node.get("NodeId")))
    found.text = ET.tostring(root, encoding="unicode")
    return found


def _holds_nested_structure(value: ET.Element) -> bool:
    """An ExtensionObject whose body holds another one (a ``TypeId`` below a ``Body``)."""
    for body in value.iter():
        if body.tag.endswith("}Body") and any(
            inner.tag.endswith("}TypeId") for inner in body.iter() if inner is not body
        ):
            return True
    return False


async def load_models(server: Server, folder: Path) -> None:
    """Import the seven files from ``folder`` and generate their structures' classes."""
    missing = missing_files(folder)
    if missing:
        raise ModelLoadError(
            f"the OPC UA models are not in {folder} (missing {', '.join(missing)}): "
            f"run `{FETCH_COMMAND}` (needs npm)"
        )
    started_s = time.monotonic()
    subtyped: dict[str, set[str]] = {}
    for name in NODESET_FILES:
        readable = readable_nodeset(folder / name)
        subtyped.update(readable.subtyped_fields)
        if readable.dropped_values:
            LOG.debug("%s: default values not read: %s", name, readable.dropped_values)
        if name == DI_FILE:
            await _import_di(server, readable.text)
        else:
            await server.import_xml(xmlstring=readable.text, strict_mode=True)
    await complete_structures(server, subtyped)
    await generate_classes(server, subtyped)
    LOG.info("OPC UA models loaded in %.1f s", time.monotonic() - started_s)


async def _import_di(server: Server, text: str) -> None:
    """DI without its parentless DesignToolOnly objects (gap 1); any other node refused is
    an error."""
    importer_log = logging.getLogger("asyncua.common.xmlimporter")
    level = importer_log.level
    importer_log.setLevel(logging.CRITICAL)  # the nine refusals are expected; others checked below
    try:
        added = await server.import_xml(xmlstring=text, strict_mode=False)
    finally:
        importer_log.setLevel(level)
    di = await server.get_namespace_index(MODEL_URIS[0])
    wanted = [
        node_id(int(item.get("NodeId", "").rsplit("=", 1)[-1]), di)
        for item in ET.fromstring(text)
        if item.get("NodeId", "").startswith("ns=1;i=")
    ]
    imported = set(added)
    lost = [
        node
        for node in wanted
        if node not in imported and node.Identifier not in DI_DESIGN_TOOL_ONLY
    ]
    if lost:
        raise ModelLoadError(f"DI: {len(lost)} nodes not imported, e.g. {lost[0].to_string()}")


async def complete_structures(server: Server, subtyped: dict[str, set[str]]) -> None:
    """Each structure of the models with its supertype's fields first (gap 3), and the
    ``StructureWithSubtypedValues`` its file names (gap 4), in the address space."""
    ours = {await server.get_namespace_index(uri) for uri in MODEL_URIS}

    async def walk(node: Any, inherited: list[ua.StructureField]) -> None:
        for child in await node.get_children(refs=ua.ObjectIds.HasSubtype):
            fields = inherited
            definition = await _definition_of(child)
            if definition is not None:
                if child.nodeid.NamespaceIndex in ours:
                    name = (await child.read_browse_name()).Name
                    if _complete(definition, inherited, subtyped.get(name, set())):
                        await child.write_attribute(
                            ua.AttributeIds.DataTypeDefinition,
                            ua.DataValue(ua.Variant(definition)),
                        )
                fields = list(definition.Fields or [])
            await walk(child, fields)

    await walk(server.get_node(node_id(ua.ObjectIds.Structure)), [])


async def _definition_of(node: Any) -> ua.StructureDefinition | None:
    try:
        definition = await node.read_data_type_definition()
    except ua.UaError:
        return None
    return definition if isinstance(definition, ua.StructureDefinition) else None


def _complete(
    definition: ua.StructureDefinition, inherited: list[ua.StructureField], subtyped: set[str]
) -> bool:
    """Change ``definition`` in place; True if it changed."""
    changed = False
    own = list(definition.Fields or [])
    if inherited and [f.Name for f in own[: len(inherited)]] != [f.Name for f in inherited]:
        definition.Fields = [*inherited, *own]
        changed = True
    if subtyped:
        # OPC 10000-3: in a StructureWithSubtypedValues, IsOptional says "allows subtypes"
        for item in definition.Fields:
            item.IsOptional = item.Name in subtyped
        definition.StructureType = ua.StructureType.StructureWithSubtypedValues
        return True
    if changed and any(item.IsOptional for item in definition.Fields):
        definition.StructureType = ua.StructureType.StructureWithOptionalFields
    return changed


async def generate_classes(server: Server, subtyped: dict[str, set[str]]) -> None:
    """The Python classes of the models' structures from the completed definitions (classes
    asyncua made while importing are replaced); a field that allows subtypes of a structure
    is an ExtensionObject (gap 4)."""
    ours = {await server.get_namespace_index(uri) for uri in MODEL_URIS}
    for name, value in list(vars(ua).items()):
        data_type = getattr(value, "data_type", None)
        ours_too = isinstance(data_type, ua.NodeId) and data_type.NamespaceIndex in ours
        if isinstance(value, type) and ours_too:
            delattr(ua, name)
    await load_data_type_definitions(server, overwrite_existing=True)
    for name in subtyped:
        cls = getattr(ua, name, None)
        if cls is None:
            continue
        definition = await _definition_of(server.get_node(cls.data_type))
        if definition is None:
            continue
        encoding_fields = []
        for item in definition.Fields:
            copy = ua.StructureField(**{k: getattr(item, k) for k in item.__dataclass_fields__})
            if item.IsOptional:  # allows subtypes: any structure, as an ExtensionObject
                copy.DataType = node_id(ua.ObjectIds.Structure)
                copy.IsOptional = False
            encoding_fields.append(copy)
        encoding = ua.StructureDefinition(
            DefaultEncodingId=definition.DefaultEncodingId,
            BaseDataType=definition.BaseDataType,
            StructureType=ua.StructureType.Structure,
            Fields=encoding_fields,
        )
        generated = make_structure(cls.data_type, name, encoding)[name]
        generated.data_type = cls.data_type  # type: ignore[attr-defined]
        delattr(ua, name)  # asyncua keeps a name's first class
        ua.register_extension_object(name, definition.DefaultEncodingId, generated, cls.data_type)
