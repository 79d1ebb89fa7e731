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
│   │                                    recorder's wear_service_threshold, WarningValues
│   │                                    0.8 and 0.95 of it
│   ├── StickSlipIntensity               (all time), both StartValue 0, unit "one"
│   ├── StickSlipServiceDue              the forecast date of the threshold (DateTime),
│   ├── StickSlipServiceDueEarly/Late    its 80 % interval
│   └── StickSlipTighteningsToService    the tightenings left to it (Int32)
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

from asyncua import Server, ua
from asyncua.common.node import Node

from services.opcua.asset_nodes import (
    FUNCTIONAL_GROUP_TYPE,
    AssetNodes,
    Figures,
    asset_namespaces,
)
from services.opcua.joining_systems import drop_placeholders
from services.opcua.nodeset_loading import node_id
from services.opcua.result_encoding import eu_information
from services.opcua.result_values import NEWTON_METRE, EngineeringUnit, utc_time
from services.opcua.tool_values import ToolCounters

#: numeric ids in IJT Base, Machinery and DI
TOOL_INTERFACE = 1004  # IToolType
TOOL_TYPE_DECLARATION = 6133  # IToolType/Parameters/Type (its EnumStrings are copied)
OPERATION_COUNTER_TYPE = 1009  # MachineryOperationCounterType
LIFETIME_COUNTER_TYPE = 1015  # MachineryLifetimeCounterType
LIFETIME_VARIABLE_TYPE = 468  # DI
#: the unit of a dimensionless figure (UNECE C62, "one")
ONE = EngineeringUnit("C62", "1", "one")
TOOL_TYPE_OTHER = 0

V = ua.VariantType


def tool_browse_name(tool_id: int) -> str:
    return f"Tool_{tool_id}"


def _utc(time_ns: int | None) -> datetime | None:
    return None if time_ns is None else utc_time(time_ns)


def _figures(counters: ToolCounters) -> Figures:
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
        "LifetimeCounters/StickSlipIntensitySinceService/WarningValues": (
            counters.intensity_warnings,
            V.Double,
        ),
        "LifetimeCounters/StickSlipIntensity": (counters.intensity_total, V.Double),
        "LifetimeCounters/StickSlipServiceDue": (_utc(counters.service_due_ns), V.DateTime),
        "LifetimeCounters/StickSlipServiceDueEarly": (
            _utc(counters.service_due_early_ns),
            V.DateTime,
        ),
        "LifetimeCounters/StickSlipServiceDueLate": (
            _utc(counters.service_due_late_ns),
            V.DateTime,
        ),
        "LifetimeCounters/StickSlipTighteningsToService": (
            counters.tightenings_to_service,
            V.Int32,
        ),
    }


class ToolAssets:
    """The Tools folder of one joining system, and its tools' nodes."""

    def __init__(self, server: Server, station: str, folder: Node, names: dict[str, int]) -> None:
        self._server = server
        self._station = station
        self._folder = folder
        self._ns = names
        self._tools: dict[int, AssetNodes] = {}

    @classmethod
    async def create(cls, server: Server, station: str, system: Node) -> ToolAssets:
        names = await asset_namespaces(server)
        ijt = names["ijt"]
        folder = await system.get_child([f"{ijt}:AssetManagement", f"{ijt}:Assets", f"{ijt}:Tools"])
        return cls(server, station, folder, names)

    async def update(self, tools: list[ToolCounters]) -> None:
        """Add the tools not there yet; write every figure of each."""
        for counters in tools:
            tool = self._tools.get(counters.tool_id)
            if tool is None:
                tool = await self._add_tool(counters.tool_id)
                self._tools[counters.tool_id] = tool
            await tool.write(self._server, _figures(counters))

    async def _add_tool(self, tool_id: int) -> AssetNodes:
        ours, ijt, di, machinery = (self._ns[k] for k in ("ours", "ijt", "di", "machinery"))
        prefix = f"{self._station}/tools/{tool_id}"
        tool = await AssetNodes.add(
            self._folder, prefix, tool_browse_name(tool_id), TOOL_INTERFACE, self._ns
        )
        lifetime = await tool.group(
            "LifetimeCounters",
            tool.node,
            (machinery, "LifetimeCounters"),
            node_id(LIFETIME_COUNTER_TYPE, machinery),
        )
        await drop_placeholders(lifetime)
        await tool.identification(("SerialNumber", "Manufacturer", "Model"))
        await tool.kind(TOOL_TYPE_DECLARATION, TOOL_TYPE_OTHER)
        counters = await tool.group(
            "OperationCounters",
            tool.node,
            (di, "OperationCounters"),
            node_id(OPERATION_COUNTER_TYPE, machinery),
        )
        await tool.variable(
            "OperationCounters/OperationCycleCounter",
            counters,
            (di, "OperationCycleCounter"),
            0,
            V.UInt32,
        )

        for name in ("StickSlipIntensitySinceService", "StickSlipIntensity"):
            path = f"LifetimeCounters/{name}"
            counter = await tool.variable(
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
            tool.variables[f"{path}/LimitValue"] = await counter.add_property(
                node_id(f"{prefix}/{path}/LimitValue", ours),
                ua.QualifiedName("LimitValue", di),
                ua.Variant(),
                datatype=node_id(ua.ObjectIds.Double),
            )
        since_service = "LifetimeCounters/StickSlipIntensitySinceService"
        warnings = await tool.variables[since_service].add_property(
            node_id(f"{prefix}/{since_service}/WarningValues", ours),
            ua.QualifiedName("WarningValues", di),
            ua.Variant(),
            datatype=node_id(ua.ObjectIds.Double),
        )
        await warnings.write_value_rank(ua.ValueRank.OneDimension)
        tool.variables[f"{since_service}/WarningValues"] = warnings
        for name in ("StickSlipServiceDue", "StickSlipServiceDueEarly", "StickSlipServiceDueLate"):
            await tool.variable(
                f"LifetimeCounters/{name}", lifetime, (ours, name), None, V.DateTime
            )
        await tool.variable(
            "LifetimeCounters/StickSlipTighteningsToService",
            lifetime,
            (ours, "StickSlipTighteningsToService"),
            None,
            V.Int32,
        )

        maintenance = await tool.group(
            "Maintenance", tool.node, (di, "Maintenance"), node_id(FUNCTIONAL_GROUP_TYPE, di)
        )
        service = await tool.group(
            "Maintenance/Service", maintenance, (ijt, "Service"), node_id(FUNCTIONAL_GROUP_TYPE, di)
        )
        await tool.variable(
            "Maintenance/Service/LastService", service, (ijt, "LastService"), None, V.DateTime
        )
        await tool.variable(
            "Maintenance/Service/ServicePlace", service, (ijt, "ServicePlace"), "", V.String
        )
        await tool.variable(
            "Maintenance/Service/ServiceCycleCount", service, (ijt, "ServiceCycleCount"), 0, V.Int32
        )
        calibration = await tool.group(
            "Maintenance/Calibration",
            maintenance,
            (ijt, "Calibration"),
            node_id(FUNCTIONAL_GROUP_TYPE, di),
        )
        await tool.variable(
            "Maintenance/Calibration/LastCalibration",
            calibration,
            (ijt, "LastCalibration"),
            None,
            V.DateTime,
        )
        value = await tool.variable(
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
        return tool
