"""The nodes of one asset (a tool, a controller) of a joining system's
``AssetManagement/Assets``: :class:`AssetNodes`.

An asset is an object with one of IJT's asset interfaces (``IToolType``,
``IControllerType``: ``HasInterface``, as IJT's own servers model them), its
children by the interface's browse names and types (OPC 40450-1, 8.3; DI's
and Machinery's building blocks), each node id ``s=<prefix>/<path>``. Its
variables are kept by path, so its figures are written by path
(:meth:`AssetNodes.write`); a figure not known is a null value.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from asyncua import Server, ua
from asyncua.common.node import Node

from services.opcua.joining_systems import BOLTWATCH_NAMESPACE, add_typed_variable
from services.opcua.nodeset_loading import IJT_BASE, MACHINERY, MODEL_URIS, node_id

#: numeric ids in Machinery and DI
COMPONENT_IDENTIFICATION_TYPE = 1005  # MachineryComponentIdentificationType (Machinery)
FUNCTIONAL_GROUP_TYPE = 1005  # DI
DI = MODEL_URIS[0]

V = ua.VariantType
#: a figure's value and type, by its path below the asset
Figures = Mapping[str, tuple[Any, ua.VariantType]]


async def asset_namespaces(server: Server) -> dict[str, int]:
    """The namespace indexes an asset's names use: ``ours``, ``ijt``, ``di``, ``machinery``."""
    return {
        "ours": await server.register_namespace(BOLTWATCH_NAMESPACE),
        "ijt": await server.get_namespace_index(IJT_BASE),
        "di": await server.get_namespace_index(DI),
        "machinery": await server.get_namespace_index(MACHINERY),
    }


def data_value(value: Any, variant_type: ua.VariantType) -> ua.DataValue:
    """``value`` of its type, or none (a DataValue without a value: asyncua refuses a Null
    variant for a variable of a type, but takes no value, and a typed one after it)."""
    if value is not None:
        return ua.DataValue(ua.Variant(value, variant_type))
    empty = ua.DataValue()
    empty.Value = None
    return empty


class AssetNodes:
    """One asset's object and its variables by path."""

    def __init__(self, node: Node, prefix: str, namespaces: dict[str, int]) -> None:
        self.node = node
        self.variables: dict[str, Node] = {}
        self._prefix = prefix
        self._ns = namespaces

    @classmethod
    async def add(
        cls, folder: Node, prefix: str, name: str, interface_id: int, namespaces: dict[str, int]
    ) -> AssetNodes:
        """A new asset ``name`` in ``folder`` with the IJT interface ``interface_id``."""
        ours, ijt = namespaces["ours"], namespaces["ijt"]
        node = await folder.add_object(node_id(prefix, ours), ua.QualifiedName(name, ours))
        await node.add_reference(
            node_id(interface_id, ijt), ua.ObjectIds.HasInterface, bidirectional=False
        )
        return cls(node, prefix, namespaces)

    async def group(self, path: str, parent: Node, name: tuple[int, str], type_id: Any) -> Node:
        """A functional group (an object of ``type_id``, None: BaseObjectType) at ``path``."""
        return await parent.add_object(
            node_id(f"{self._prefix}/{path}", self._ns["ours"]),
            ua.QualifiedName(name[1], name[0]),
            objecttype=type_id,
            instantiate_optional=False,
        )

    async def variable(
        self,
        path: str,
        parent: Node,
        name: tuple[int, str],
        value: Any,
        vtype: ua.VariantType,
        type_definition: ua.NodeId | None = None,  # None: BaseDataVariableType
    ) -> Node:
        """The variable at ``path``: the one its group's type instantiated, else a new one."""
        try:  # instantiated with its group (a mandatory child of the group's type)
            node = await parent.get_child(ua.QualifiedName(name[1], name[0]))
        except ua.UaError:
            node = await add_typed_variable(
                parent,
                node_id(f"{self._prefix}/{path}", self._ns["ours"]),
                ua.QualifiedName(name[1], name[0]),
                # typed, as asyncua wants (the figures are written right after)
                ua.Variant(ua.get_default_value(vtype) if value is None else value, vtype),
                node_id(vtype.value),  # a built-in type's id is its variant type's
                type_definition or node_id(ua.ObjectIds.BaseDataVariableType),
            )
        self.variables[path] = node
        return node

    async def identification(self, names: tuple[str, ...]) -> Node:
        """``Identification`` (MachineryComponentIdentificationType) with DI's properties
        ``names`` (SerialNumber and SoftwareRevision text, the rest localized), those its
        type did not instantiate added as properties, as DI declares them."""
        di, machinery, ours = self._ns["di"], self._ns["machinery"], self._ns["ours"]
        group = await self.group(
            "Identification",
            self.node,
            (di, "Identification"),
            node_id(COMPONENT_IDENTIFICATION_TYPE, machinery),
        )
        for name in names:
            vtype = V.String if name in ("SerialNumber", "SoftwareRevision") else V.LocalizedText
            path = f"Identification/{name}"
            try:
                node = await group.get_child(ua.QualifiedName(name, di))
            except ua.UaError:
                node = await group.add_property(
                    node_id(f"{self._prefix}/{path}", ours),
                    ua.QualifiedName(name, di),
                    ua.Variant(ua.get_default_value(vtype), vtype),
                    varianttype=vtype,
                    datatype=node_id(vtype.value),
                )
            self.variables[path] = node
        return group

    async def kind(self, declaration_id: int, value: int) -> Node:
        """``Parameters/Type``: a MultiStateDiscreteType of ``value``, with the EnumStrings
        of the interface's declaration ``declaration_id`` (IJT Base)."""
        ijt, ours = self._ns["ijt"], self._ns["ours"]
        parameters = await self.group("Parameters", self.node, (ijt, "Parameters"), None)
        node = await self.variable(
            "Parameters/Type",
            parameters,
            (ijt, "Type"),
            value,
            V.Byte,
            node_id(ua.ObjectIds.MultiStateDiscreteType),
        )
        declared = Node(self.node.session, node_id(declaration_id, ijt))
        strings = await (await declared.get_child("0:EnumStrings")).read_value()
        await node.add_property(
            node_id(f"{self._prefix}/Parameters/Type/EnumStrings", ours),
            "EnumStrings",
            strings,
            V.LocalizedText,
        )
        return node

    async def write(self, server: Server, figures: Figures) -> None:
        """Each figure into its variable."""
        for path, (value, variant_type) in figures.items():
            await server.write_attribute_value(
                self.variables[path].nodeid, data_value(value, variant_type)
            )
