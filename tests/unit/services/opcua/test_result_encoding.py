"""The models loaded into a real asyncua server (no network), and a result through them.

Needs the fetched NodeSet2 files (``make opcua-nodesets``); skipped with the
reason without them.
"""

from __future__ import annotations

import asyncio
from typing import Any

import pytest
from asyncua import Server, ua
from asyncua.ua.ua_binary import struct_from_binary, struct_to_binary

from services.opcua.alert_conditions import ConditionMethods, StationConditions
from services.opcua.alert_events import alert_event
from services.opcua.cycle_values import cycle_values
from services.opcua.event_delivery import EventDelivery
from services.opcua.joining_systems import JoiningSystem, result_browse_name
from services.opcua.nodeset_files import missing_files, nodeset_folder
from services.opcua.nodeset_loading import load_models, node_id
from services.opcua.result_encoding import model_class, result_data
from services.opcua.result_values import result_values
from services.opcua.tool_assets import ToolAssets
from services.opcua.tool_values import tool_counters
from shared.contract import AlertAck, ControllerAlarm
from shared.quality.cycle_result import cycle_result
from shared.wear import ToolWear
from tests.support import factories

if missing_files(nodeset_folder()):
    pytest.skip(
        "the OPC UA models are not fetched (`make opcua-nodesets` needs npm)",
        allow_module_level=True,
    )


async def _loaded() -> Server:
    server = Server()
    await server.init()
    await load_models(server, nodeset_folder())
    return server


async def _tools_of(server: Server, system: JoiningSystem) -> dict[str, Any]:
    """The Assets folders (no placeholders), the tools, and tool 7's values once written."""
    assets = await ToolAssets.create(server, "st1", system.node)
    wear = ToolWear(7, 5, 6.0, 1.2, None, None, 3, 2.5)
    await assets.update([tool_counters(wear, 40.0)])
    ijt = await server.get_namespace_index("http://opcfoundation.org/UA/IJT/Base/")
    folder = await system.node.get_child([f"{ijt}:AssetManagement", f"{ijt}:Assets"])
    names = sorted([(await node.read_browse_name()).Name for node in await folder.get_children()])
    tools = await folder.get_child(f"{ijt}:Tools")
    [tool] = await tools.get_children()
    values = []
    for path in (
        "OperationCounters/OperationCycleCounter",
        "LifetimeCounters/StickSlipIntensitySinceService",
        "LifetimeCounters/StickSlipIntensitySinceService/LimitValue",
        "Maintenance/Service/ServiceCycleCount",
        "Maintenance/Calibration/LastCalibration",  # not known: no value
    ):
        node = server.get_node(node_id(f"st1/tools/7/{path}", tool.nodeid.NamespaceIndex))
        written = (await node.read_data_value(raise_on_bad_status=False)).Value
        values.append(None if written is None else written.Value)
    tool_name = (await tool.read_browse_name()).Name
    return {"assets": names, "tools": [tool_name], "values": values}


async def _no_record(_ack: AlertAck) -> None:
    raise AssertionError("nothing acknowledged here")


class _Events:
    def __init__(self) -> None:
        self.received: list[Any] = []

    def event_notification(self, event: Any) -> None:
        self.received.append(event)


async def _alarm_events(
    server: Server, system: JoiningSystem, delivery: EventDelivery
) -> list[Any]:
    """A controller's alarm as its condition of the joining system, as a subscriber of its
    JoiningSystemConditionType events gets it."""
    ijt = await server.get_namespace_index("http://opcfoundation.org/UA/IJT/Base/")
    events = _Events()
    subscription = await server.create_subscription(10, events)
    await subscription.subscribe_events(system.node, server.get_node(node_id(1020, ijt)))
    alarm = ControllerAlarm(
        "st1", factories.T0, factories.T0, "E404", "raised", True, None, None, "tool not connected"
    )
    methods = ConditionMethods(server, frozenset(), _no_record)
    conditions = await StationConditions.create(server, system, delivery, methods)
    await conditions.report(alert_event(alarm))
    while not events.received:  # the subscription publishes every 10 ms
        await asyncio.sleep(0.01)
    await subscription.delete()
    return events.received


def test_the_models_load_and_a_result_round_trips_with_its_joining_metadata() -> None:
    async def scenario() -> tuple[Any, Any, list[Any], list[Any]]:
        server = await _loaded()
        ijt = await server.get_namespace_index("http://opcfoundation.org/UA/IJT/Base/")
        event_type = server.get_node(node_id(1007, ijt))
        event_fields = [
            (await child.read_browse_name()).Name for child in await event_type.get_children()
        ]
        data = result_data(result_values(factories.result(7, part_id="VIN-7")))
        decoded = struct_from_binary(
            model_class("ResultDataType"), ua.utils.Buffer(struct_to_binary(data))
        )
        delivery = await EventDelivery.create(server)
        system = await JoiningSystem.create(server, "st1", delivery)
        await system.publish("st1/7", result_browse_name(7), data, "st1/7 OK")
        names = [(await node.read_browse_name()).Name for node in await system.node.get_children()]
        tools.update(await _tools_of(server, system))
        alarms.extend(await _alarm_events(server, system, delivery))
        return data, decoded, names, event_fields

    tools: dict[str, Any] = {}
    alarms: list[Any] = []
    data, decoded, names, event_fields = asyncio.run(scenario())
    assert tools["assets"] == [
        "Accessories",
        "Batteries",
        "Cables",
        "Controllers",
        "Feeders",
        "MemoryDevices",
        "PowerSupplies",
        "Sensors",
        "Servos",
        "SoftwareComponents",
        "SubComponents",
        "Tools",
        "VirtualStations",
    ]
    assert tools["tools"] == ["Tool_7"]  # no <Tool> placeholder either
    assert tools["values"] == [5, 2.5, 40.0, 3, None]
    [alarm] = alarms  # through a subscription of the server's own session
    assert alarm.Message.Text == "E404: tool not connected"
    assert getattr(alarm, "JoiningSystemEventContent/EventCode") == 404
    assert getattr(alarm, "JoiningSystemEventContent/EventText").Text == alarm.Message.Text
    assert (alarm.Severity, alarm.ConditionClassName.Text) == (800, "ErrorConditionClassType")
    assert "Result" in event_fields  # lost without the dropped default values
    meta = decoded.ResultMetaData
    assert type(meta).__name__ == "JoiningResultMetaDataType"  # a subtype, as the model allows
    assert meta.ResultId == "st1/7"
    assert meta.PartId == "VIN-7"  # inherited from ResultMetaDataType (completed definition)
    assert meta.Classification == 1
    assert meta.Name == data.ResultMetaData.Name
    assert {pair.Key for pair in meta.ExtendedMetaData} >= {"StopReason", "Station"}
    [content] = decoded.ResultContent
    torque = content.Value.OverallResultValues[0]
    assert (torque.Name, torque.MeasuredValue, torque.EngineeringUnits.UnitId) == (
        "Torque",
        190.0,
        20053,
    )
    assert "ResultManagement" in names and "AssetManagement" in names


def _round_trip(data: Any) -> Any:
    return struct_from_binary(
        model_class("ResultDataType"), ua.utils.Buffer(struct_to_binary(data))
    )


def test_a_cycle_s_sync_result_round_trips_with_references_to_its_spindles_results() -> None:
    spindles = {
        n: factories.result(30 + n, spindle=n, sync_id=9, result=verdict)
        for n, verdict in ((1, "OK"), (2, "NOK"))
    }

    async def scenario() -> tuple[Any, Any]:
        await _loaded()  # the models' classes
        cycle = _round_trip(result_data(cycle_values(cycle_result("st1", 9, 2, spindles))))
        spindle = _round_trip(result_data(result_values(spindles[2])))
        return cycle, spindle

    cycle, spindle = asyncio.run(scenario())
    meta = cycle.ResultMetaData
    assert type(meta).__name__ == "JoiningResultMetaDataType"
    assert (meta.ResultId, meta.Classification, meta.SequenceNumber) == ("st1/cycle/9", 2, 9)
    assert meta.ResultEvaluation == 2 and meta.ResultEvaluationDetails.Text == "spindle 2 NOK"
    [total] = meta.ResultCounters
    assert (total.CounterType, total.CounterValue) == (9, 2)  # TOTAL_NUMBER_OF_SPINDLES
    references = [item.Value for item in cycle.ResultContent]
    assert [type(ref).__name__ for ref in references] == ["ResultDataType"] * 2
    assert [
        (
            ref.ResultMetaData.ResultId,
            ref.ResultMetaData.Classification,
            ref.ResultMetaData.ResultEvaluation,
            [(c.CounterType, c.CounterValue) for c in ref.ResultMetaData.ResultCounters],
            ref.ResultContent,
        )
        for ref in references
    ] == [("st1/31", 1, 1, [(7, 1)], []), ("st1/32", 1, 2, [(7, 2)], [])]
    [counter] = spindle.ResultMetaData.ResultCounters  # the spindle's own result names it
    assert (counter.Name, counter.CounterType, counter.CounterValue) == ("Spindle", 7, 2)
    assert {pair.Key: pair.Value.Value for pair in spindle.ResultMetaData.ExtendedMetaData}[
        "SyncId"
    ] == "9"
