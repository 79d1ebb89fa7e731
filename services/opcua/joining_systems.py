"""One IJT joining system per station, and a result put into it.

Each station served is an instance of IJT Base's ``JoiningSystemType`` in
Machinery's ``Machines`` folder, its node id ``ns=<boltwatch>;s=<station>``
and its browse name the station's id. asyncua instantiates the type's mandatory
children (AssetManagement, Identification, JoiningProcessManagement,
JointManagement, MachineryBuildingBlocks, ResultManagement with its methods and
its ``Results`` folder), and instances of the type's placeholders too, which are
deleted (:func:`drop_placeholders`; ``AssetManagement/Assets/Tools`` gets the
station's tools from :mod:`.tool_assets`). What :meth:`JoiningSystem.publish`
does with a result:

- ``ResultManagement/Results``: a variable of ``JoiningSystemResultType``
  (data type ``ResultDataType``) named ``Result_<run id>`` (a browse name
  without ``/``, which browse paths use), its node id
  ``s=<station>/results/<ResultId>``; the newest
  :data:`KEPT_RESULTS` stay, the oldest go (a client reads the latest there);
- a ``JoiningSystemResultReadyEventType`` event from the joining system, its
  ``Result`` the same ``ResultDataType`` (a client subscribes to the joining
  system's events). The model marks the type abstract; IJT's own servers send
  it as it is, and so does this one.

:meth:`JoiningSystem.report` emits a ``JoiningSystemEventType`` event (abstract
too) of an alert or a controller's alarm (:mod:`.alert_events`), its
``JoiningSystemEventContent`` with ``EventCode``, ``EventText`` and
``JoiningTechnology``, its ``ConditionClassId``/``Name`` and ``Severity``.

ResultManagement's methods as the instance has them (``GetResultById``,
``GetLatestResult``, ``GetResultIdListFiltered``, ``ReleaseResultHandle``) are
linked by the service (:mod:`.result_requests`); the methods of the other
management objects are in the address space as the type has them, without an
implementation (a call answers ``BadNothingToDo``, asyncua's answer for a method
without one).
"""

from __future__ import annotations

import logging
from collections import deque
from typing import Any

from asyncua import Server, ua
from asyncua.common.manage_nodes import delete_nodes
from asyncua.common.node import Node

from services.opcua.alert_events import AlertEvent
from services.opcua.nodeset_loading import IJT_BASE, MACHINERY_RESULT, node_id
from services.opcua.result_values import JOINING_TECHNOLOGY, utc_time
from services.opcua.system_identification import SystemIdentification

LOG = logging.getLogger(__name__)

#: the application's own namespace (its joining systems and results)
BOLTWATCH_NAMESPACE = "urn:boltwatch:opcua"
#: results kept per station in ResultManagement/Results
KEPT_RESULTS = 20
#: numeric ids in IJT Base, Machinery and Machinery/Result
JOINING_SYSTEM_TYPE = 1005
JOINING_SYSTEM_RESULT_TYPE = 2014
RESULT_READY_EVENT_TYPE = 1007
JOINING_SYSTEM_EVENT_TYPE = 1006
EVENT_CONTENT = "JoiningSystemEventContent"
MACHINES_FOLDER = 1001
RESULT_DATA_TYPE = 3008
MACHINERY = "http://opcfoundation.org/UA/Machinery/"
#: the joining system's folder of Machinery's building blocks
BUILDING_BLOCKS = "MachineryBuildingBlocks"


def result_browse_name(run_id: int) -> str:
    """The browse name of a run's result in its station's Results folder."""
    return f"Result_{run_id}"


class JoiningSystem:
    """A station's joining system in the address space, with its event generator."""

    def __init__(
        self,
        station: str,
        node: Node,
        results: Node,
        generators: tuple[Any, Any],
        names: tuple[int, int, int],
    ) -> None:
        self.station = station
        self.node = node
        self._results = results
        self._events, self._alerts = generators
        self._names = names
        self._kept: deque[Node] = deque()

    @classmethod
    async def create(cls, server: Server, station: str) -> JoiningSystem:
        ours = await server.register_namespace(BOLTWATCH_NAMESPACE)
        ijt = await server.get_namespace_index(IJT_BASE)
        machinery = await server.get_namespace_index(MACHINERY)
        result_ns = await server.get_namespace_index(MACHINERY_RESULT)
        machines = server.get_node(node_id(MACHINES_FOLDER, machinery))
        node = await machines.add_object(
            node_id(station, ours),
            ua.QualifiedName(station, ours),
            objecttype=node_id(JOINING_SYSTEM_TYPE, ijt),
        )
        await drop_placeholders(node)
        await share_building_blocks(node)
        results = await node.get_child([f"{result_ns}:ResultManagement", f"{result_ns}:Results"])
        events = await server.get_event_generator(
            node_id(RESULT_READY_EVENT_TYPE, ijt), emitting_node=node.nodeid
        )
        alerts = await server.get_event_generator(
            node_id(JOINING_SYSTEM_EVENT_TYPE, ijt), emitting_node=node.nodeid
        )
        names = (ours, ijt, result_ns)
        LOG.info("joining system %s at %s", station, node.nodeid.to_string())
        return cls(station, node, results, (events, alerts), names)

    async def result_management_method(self, name: str) -> Node:
        """A method of the joining system's ResultManagement (e.g. ``GetResultById``)."""
        _ours, _ijt, result_ns = self._names
        return await self.node.get_child([f"{result_ns}:ResultManagement", f"{result_ns}:{name}"])

    async def publish(self, result_id: str, run_id: int, result: Any, message: str) -> None:
        """``result`` (a ``ua.ResultDataType``) into Results, then the result-ready event."""
        ours, ijt, result_ns = self._names
        variable = await add_typed_variable(
            self._results,
            node_id(f"{self.station}/results/{result_id}", ours),
            ua.QualifiedName(result_browse_name(run_id), ours),
            ua.Variant(result, ua.VariantType.ExtensionObject),
            node_id(RESULT_DATA_TYPE, result_ns),
            node_id(JOINING_SYSTEM_RESULT_TYPE, ijt),
        )
        self._kept.append(variable)
        while len(self._kept) > KEPT_RESULTS:
            await remove_child(
                self._results, self._kept.popleft(), node_id(ua.ObjectIds.HasComponent)
            )
        self._events.event.Result = ua.Variant(result, ua.VariantType.ExtensionObject)
        self._events.event.Severity = 100
        await self._events.trigger(message=message)

    async def identify(self, identification: SystemIdentification) -> None:
        """Write the joining system's ``Identification`` (its properties, instantiated with
        the type, have no value until then)."""
        group = (await _children_by_name(self.node))["Identification"]
        texts = {
            "Name": (identification.name, ua.VariantType.String),
            "SystemId": (identification.system_id, ua.VariantType.String),
            "Location": (identification.location, ua.VariantType.String),
            "Description": (
                ua.LocalizedText(identification.description),
                ua.VariantType.LocalizedText,
            ),
            "JoiningTechnology": (
                ua.LocalizedText(identification.joining_technology),
                ua.VariantType.LocalizedText,
            ),
        }
        by_name = await _children_by_name(group)
        for name, (value, variant_type) in texts.items():
            if value is not None:
                await by_name[name].write_value(ua.Variant(value, variant_type))

    async def report(self, alert: AlertEvent) -> None:
        """A ``JoiningSystemEventType`` event of an alert or a controller's alarm."""
        _ours, ijt, _result_ns = self._names
        event = self._alerts.event
        # the event type's JoiningSystemEventContent holds variables, which asyncua's event
        # object leaves out (it takes properties): its fields by their browse paths
        event.add_property(f"{EVENT_CONTENT}/EventCode", alert.code, ua.VariantType.Int64)
        event.add_property(
            f"{EVENT_CONTENT}/EventText", ua.LocalizedText(alert.text), ua.VariantType.LocalizedText
        )
        event.add_property(
            f"{EVENT_CONTENT}/JoiningTechnology",
            ua.LocalizedText(JOINING_TECHNOLOGY),
            ua.VariantType.LocalizedText,
        )
        class_id, class_name = alert.condition_class
        event.ConditionClassId = node_id(class_id, ijt)
        event.ConditionClassName = ua.LocalizedText(class_name)
        event.Severity = alert.severity
        await self._alerts.trigger(time_attr=utc_time(alert.time_ns), message=alert.text)


async def _children_by_name(node: Node) -> dict[str, Node]:
    """``node``'s children by their browse names (whatever their namespaces)."""
    return {
        str((await child.read_browse_name()).Name): child for child in await node.get_children()
    }


async def drop_placeholders(node: Node) -> None:
    """Delete the instances asyncua made of a type's placeholders (``<Tool>``,
    ``<LifetimeVariable>``...): a placeholder says what may be there, it is no node of an
    instance (OPC 10000-3, 6.4.4.4.4)."""
    for child in await node.get_children_descriptions(refs=ua.ObjectIds.HierarchicalReferences):
        name = child.BrowseName.Name
        if name.startswith("<") and name.endswith(">"):
            await remove_child(node, Node(node.session, child.NodeId), child.ReferenceTypeId)
        elif child.NodeClass == ua.NodeClass.Object:  # where the placeholders are
            await drop_placeholders(Node(node.session, child.NodeId))


async def share_building_blocks(node: Node) -> None:
    """``MachineryBuildingBlocks`` referring to the joining system's own ``Identification`` and
    ``ResultManagement``, not to copies of them.

    In the type the folder's ``HasAddIn`` references lead to the same instance declarations
    as the type's own (one object, referenced twice); asyncua instantiates each reference
    as a node of its own, so the folder held a second ResultManagement without its methods'
    implementations and a second Identification without values. Each such copy (a child of
    the folder with the browse name of a child of the joining system) is deleted and the
    folder refers to the joining system's own object, with the reference type it had."""
    own = {
        (child.BrowseName.NamespaceIndex, child.BrowseName.Name): child.NodeId
        for child in await node.get_children_descriptions(refs=ua.ObjectIds.HierarchicalReferences)
    }
    blocks_name = next((name for name in own if name[1] == BUILDING_BLOCKS), None)
    if blocks_name is None:
        return
    blocks = Node(node.session, own[blocks_name])
    for child in await blocks.get_children_descriptions(refs=ua.ObjectIds.HierarchicalReferences):
        target = own.get((child.BrowseName.NamespaceIndex, child.BrowseName.Name))
        if target is None or target == child.NodeId:
            continue
        await remove_child(blocks, Node(node.session, child.NodeId), child.ReferenceTypeId)
        await blocks.add_reference(target, child.ReferenceTypeId, forward=True, bidirectional=False)


async def remove_child(parent: Node, child: Node, reference_type: ua.NodeId) -> None:
    """``child`` and the nodes below it deleted, and ``parent``'s reference to it.

    Not ``Node.delete()``: asyncua's server then looks through every node of the address
    space for references to each node deleted (about 0.1 s a node with the models loaded).
    Only the parent refers to these nodes (and they to each other)."""
    await parent.delete_reference(child.nodeid, reference_type, forward=True, bidirectional=False)
    await delete_nodes(parent.session, [child], recursive=True, delete_target_references=False)


async def add_typed_variable(
    parent: Node,
    nodeid: ua.NodeId,
    name: ua.QualifiedName,
    value: ua.Variant,
    datatype: ua.NodeId,
    type_definition: ua.NodeId,
) -> Node:
    """A read-only scalar variable of ``type_definition`` (e.g. a result's
    JoiningSystemResultType; its sub-variables are not instantiated), a component of
    ``parent``. asyncua's ``add_variable`` makes a BaseDataVariableType, and a type definition
    changed after stays BaseDataVariableType in the parent's reference: a browse (a
    generic client's tree) showed that."""
    attributes = ua.VariableAttributes(
        DisplayName=ua.LocalizedText(name.Name),
        Description=ua.LocalizedText(name.Name),
        Value=value,
        DataType=datatype,
        ValueRank=ua.ValueRank.Scalar,
        WriteMask=0,
        UserWriteMask=0,
        AccessLevel=ua.AccessLevel.CurrentRead.mask,
        UserAccessLevel=ua.AccessLevel.CurrentRead.mask,
        Historizing=False,
    )
    item = ua.AddNodesItem(
        ParentNodeId=parent.nodeid,
        ReferenceTypeId=node_id(ua.ObjectIds.HasComponent),
        RequestedNewNodeId=nodeid,
        BrowseName=name,
        NodeClass=ua.NodeClass.Variable,
        NodeAttributes=attributes,
        TypeDefinition=type_definition,
    )
    [added] = await parent.session.add_nodes([item])
    added.StatusCode.check()
    return Node(parent.session, added.AddedNodeId)
