"""A station's tools in its joining system's ``AssetManagement/Assets/Tools``, with their
lifetime counters from the wear ledger.

Each tool the station's wear ledger knows (``tools(station=...)``) is an
object ``Tool_<tool id>`` (node id ``s=<station>/tools/<tool id>``) with IJT's
``IToolType`` interface (``HasInterface``, as IJT's own servers model assets),
its children by the interface's browse names and types (OPC 40450-1, 8.3;
DI's and Machinery's building blocks); the figures are :mod:`.tool_values`':

```
Tool_7                          BaseObjectType, HasInterface IToolType
├── Identification              MachineryComponentIdentificationType: SerialNumber,
│                               Manufacturer (empty: not known), Model
├── Parameters/Type             MultiStateDiscreteType, 0 (OTHER: not known), the
│                               model's EnumStrings
├── OperationCounters           MachineryOperationCounterType: OperationCycleCounter
├── LifetimeCounters            MachineryLifetimeCounterType:
│   ├── StickSlipIntensitySinceService   LifetimeVariableType: LimitValue the
│   │                                    recorder's wear_service_threshold
│   └── StickSlipIntensity               (all time), both StartValue 0, unit "one"
└── Maintenance                 FunctionalGroupType
    ├── Service                 LastService, ServicePlace (empty), ServiceCycleCount
    └── Calibration             LastCalibration, CalibrationValue (N·m)
```

A figure not known (no controller spoke of the tool, no threshold set) is a
null value. :meth:`ToolAssets.update` adds the tools not there yet and writes
every value; the service calls it at start, after each result and every few
seconds (the recorder adds a run to the ledger when its summary comes).
"""

from __future__ import annotations

from datetime import datetime
from typing import Any

from asyncua import Server, ua
from asyncua.common.node import Node

from services.opcua.joining_systems import (
    BOLTWATCH_NAMESPACE,
    MACHINERY,
    add_typed_variable,
    drop_placeholders,
)
from services.opcua.nodeset_loading import IJT_BASE, MODEL_URIS, node_id
from services.opcua.result_encoding import eu_information
from services.opcua.result_values import NEWTON_METRE, EngineeringUnit, utc_time
from services.opcua.tool_values import ToolCounters

#: numeric ids in IJT Base, Machinery and DI
TOOL_INTERFACE = 1004  # IToolType
TOOL_TYPE_DECLARATION = 6133  # IToolType/Parameters/Type (its EnumStrings are copied)
COMPONENT_IDENTIFICATION_TYPE = 1005  # MachineryComponentIdentificationType (Machinery)
OPERATION_COUNTER_TYPE = 1009  # MachineryOperationCounterType
LIFETIME_COUNTER_TYPE = 1015  # MachineryLifetimeCounterType
FUNCTIONAL_GROUP_TYPE = 1005  # DI
LIFETIME_VARIABLE_TYPE = 468  # DI
DI = MODEL_URIS[0]
#: the unit of a dimensionless figure (UNECE C62, "one")
ONE = EngineeringUnit("C62", "1", "one")
TOOL_TYPE_OTHER = 0

V = ua.VariantType


def tool_browse_name(tool_id: int) -> str:
    return f"Tool_{tool_id}"


def _utc(time_ns: int | None) -> datetime | None:
    return None if time_ns is None else utc_time(time_ns)


def _data_value(value: Any, variant_type: ua.VariantType) -> ua.DataValue:
    """``value`` of its type, or none (a DataValue without a value: asyncua refuses a Null
    variant for a variable of a type, but takes no value, and a typed one after it)."""
    if value is not None:
        return ua.DataValue(ua.Variant(value, variant_type))
    empty = ua.DataValue()
    empty.Value = None
    return empty


def _figures(counters: ToolCounters) -> dict[str, tuple[Any, ua.VariantType]]:
    """Each variable's path below the tool, its value and type."""
    return {
        "Identification/SerialNumber": (counters.serial_number, V.String),
        "Identification/Model": (
            None if counters.model is None else ua.LocalizedText(counters.model),
            V.LocalizedText,
        ),
        "OperationCounters/OperationCycleCounter": (counters.tightenings, V.UInt32),
        "Maintenance/Service/ServiceCycleCount": (counters.tightenings_since_service, V.Int32),
        "Maintenance/Service/LastService": (_utc(counters.last_service_ns), V.DateTime),
        "Maintenance/Calibration/LastCalibration": (
            _utc(counters.last_calibration_ns),
            V.DateTime,
        ),
        "Maintenance/Calibration/CalibrationValue": (counters.calibration_value_nm, V.Double),
        "LifetimeCounters/StickSlipIntensitySinceService": (
            counters.intensity_since_service,
            V.Double,
        ),
        "LifetimeCounters/StickSlipIntensitySinceService/LimitValue": (
            counters.intensity_threshold,
            V.Double,
        ),
        "LifetimeCounters/StickSlipIntensity": (counters.intensity_total, V.Double),
    }


class ToolAssets:
    """The Tools folder of one joining system, and the value nodes of its tools."""

    def __init__(self, server: Server, station: str, folder: Node, names: dict[str, int]) -> None:
        self._server = server
        self._station = station
        self._folder = folder
        self._ns = names
        self._variables: dict[int, dict[str, Node]] = {}

    @classmethod
    async def create(cls, server: Server, station: str, system: Node) -> ToolAssets:
        names = {
            "ours": await server.register_namespace(BOLTWATCH_NAMESPACE),
            "ijt": await server.get_namespace_index(IJT_BASE),
            "di": await server.get_namespace_index(DI),
            "machinery": await server.get_namespace_index(MACHINERY),
        }
        ijt = names["ijt"]
        folder = await system.get_child([f"{ijt}:AssetManagement", f"{ijt}:Assets", f"{ijt}:Tools"])
        return cls(server, station, folder, names)

    async def update(self, tools: list[ToolCounters]) -> None:
        """Add the tools not there yet; write every figure of each."""
        for counters in tools:
            variables = self._variables.get(counters.tool_id)
            if variables is None:
                variables = await self._add_tool(counters.tool_id)
                self._variables[counters.tool_id] = variables
            for path, (value, variant_type) in _figures(counters).items():
                await self._server.write_attribute_value(
                    variables[path].nodeid, _data_value(value, variant_type)
                )

    async def _add_tool(self, tool_id: int) -> dict[str, Node]:
        ours, ijt, di, machinery = (self._ns[k] for k in ("ours", "ijt", "di", "machinery"))
        prefix = f"{self._station}/tools/{tool_id}"
        tool = await self._folder.add_object(
            node_id(prefix, ours), ua.QualifiedName(tool_browse_name(tool_id), ours)
        )
        await tool.add_reference(
            node_id(TOOL_INTERFACE, ijt), ua.ObjectIds.HasInterface, bidirectional=False
        )
        nodes: dict[str, Node] = {}

        async def group(path: str, parent: Node, name: tuple[int, str], type_id: Any) -> Node:
            return await parent.add_object(
                node_id(f"{prefix}/{path}", ours),
                ua.QualifiedName(name[1], name[0]),
                objecttype=type_id,
                instantiate_optional=False,
            )

        async def variable(
            path: str,
            parent: Node,
            name: tuple[int, str],
            value: Any,
            vtype: ua.VariantType,
            type_definition: ua.NodeId | None = None,  # None: BaseDataVariableType
        ) -> Node:
            try:  # instantiated with its group (a mandatory child of the group's type)
                node = await parent.get_child(ua.QualifiedName(name[1], name[0]))
            except ua.UaError:
                node = await add_typed_variable(
                    parent,
                    node_id(f"{prefix}/{path}", ours),
                    ua.QualifiedName(name[1], name[0]),
                    # typed, as asyncua wants (the figures are written right after)
                    ua.Variant(ua.get_default_value(vtype) if value is None else value, vtype),
                    node_id(vtype.value),  # a built-in type's id is its variant type's
                    type_definition or node_id(ua.ObjectIds.BaseDataVariableType),
                )
            nodes[path] = node
            return node

        lifetime = await group(
            "LifetimeCounters",
            tool,
            (machinery, "LifetimeCounters"),
            node_id(LIFETIME_COUNTER_TYPE, machinery),
        )
        await drop_placeholders(lifetime)
        identification = await group(
            "Identification",
            tool,
            (di, "Identification"),
            node_id(COMPONENT_IDENTIFICATION_TYPE, machinery),
        )
        await variable(
            "Identification/SerialNumber", identification, (di, "SerialNumber"), "", V.String
        )
        await variable(
            "Identification/Manufacturer",
            identification,
            (di, "Manufacturer"),
            ua.LocalizedText(""),
            V.LocalizedText,
        )
        await variable("Identification/Model", identification, (di, "Model"), None, V.LocalizedText)

        parameters = await group("Parameters", tool, (ijt, "Parameters"), None)
        tool_type = await variable(
            "Parameters/Type",
            parameters,
            (ijt, "Type"),
            TOOL_TYPE_OTHER,
            V.Byte,
            node_id(ua.ObjectIds.MultiStateDiscreteType),
        )
        declared = self._server.get_node(node_id(TOOL_TYPE_DECLARATION, ijt))
        strings = await (await declared.get_child("0:EnumStrings")).read_value()
        await tool_type.add_property(
            node_id(f"{prefix}/Parameters/Type/EnumStrings", ours),
            "EnumStrings",
            strings,
            V.LocalizedText,
        )

        counters = await group(
            "OperationCounters",
            tool,
            (di, "OperationCounters"),
            node_id(OPERATION_COUNTER_TYPE, machinery),
        )
        await variable(
            "OperationCounters/OperationCycleCounter",
            counters,
            (di, "OperationCycleCounter"),
            0,
            V.UInt32,
        )

        for name in ("StickSlipIntensitySinceService", "StickSlipIntensity"):
            path = f"LifetimeCounters/{name}"
            counter = await variable(
                path, lifetime, (ours, name), 0.0, V.Double, node_id(LIFETIME_VARIABLE_TYPE, di)
            )
            await counter.add_property(
                node_id(f"{prefix}/{path}/EngineeringUnits", ours),
                "EngineeringUnits",
                eu_information(ONE),
            )
            await counter.add_property(
                node_id(f"{prefix}/{path}/StartValue", ours),
                ua.QualifiedName("StartValue", di),
                0.0,
                V.Double,
            )
            nodes[f"{path}/LimitValue"] = await counter.add_property(
                node_id(f"{prefix}/{path}/LimitValue", ours),
                ua.QualifiedName("LimitValue", di),
                ua.Variant(),
                datatype=node_id(ua.ObjectIds.Double),
            )

        maintenance = await group(
            "Maintenance", tool, (di, "Maintenance"), node_id(FUNCTIONAL_GROUP_TYPE, di)
        )
        service = await group(
            "Maintenance/Service", maintenance, (ijt, "Service"), node_id(FUNCTIONAL_GROUP_TYPE, di)
        )
        await variable(
            "Maintenance/Service/LastService", service, (ijt, "LastService"), None, V.DateTime
        )
        await variable(
            "Maintenance/Service/ServicePlace", service, (ijt, "ServicePlace"), "", V.String
        )
        await variable(
            "Maintenance/Service/ServiceCycleCount", service, (ijt, "ServiceCycleCount"), 0, V.Int32
        )
        calibration = await group(
            "Maintenance/Calibration",
            maintenance,
            (ijt, "Calibration"),
            node_id(FUNCTIONAL_GROUP_TYPE, di),
        )
        await variable(
            "Maintenance/Calibration/LastCalibration",
            calibration,
            (ijt, "LastCalibration"),
            None,
            V.DateTime,
        )
        value = await variable(
            "Maintenance/Calibration/CalibrationValue",
            calibration,
            (ijt, "CalibrationValue"),
            None,
            V.Double,
        )
        await value.add_property(
            node_id(f"{prefix}/Maintenance/Calibration/CalibrationValue/EngineeringUnits", ours),
            "EngineeringUnits",
            eu_information(NEWTON_METRE),
        )
        return nodes
