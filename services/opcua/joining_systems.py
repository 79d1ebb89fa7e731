"""One IJT joining system per station, and a result put into it.

Each station served is an instance of IJT Base's ``JoiningSystemType`` in
Machinery's ``Machines`` folder, its node id ``ns=<boltwatch>;s=<station>``
and its browse name the station's id. asyncua instantiates the type's mandatory
children (AssetManagement, Identification, JoiningProcessManagement,
JointManagement, MachineryBuildingBlocks, ResultManagement with its methods and
its ``Results`` folder), and instances of the type's placeholders too, which are
deleted (:func:`drop_placeholders`; ``AssetManagement/Assets/Tools`` gets the
station's tools from :mod:`.tool_assets`); ``MachineryBuildingBlocks`` refers to its
own Identification and ResultManagement (:func:`share_building_blocks`). The joining
system is an event notifier below ``Machines`` (:class:`~.event_delivery.EventDelivery`:
its events reach a client subscribed on it, on ``Machines`` or on the Server object).
What :meth:`JoiningSystem.publish` does with a result:

- ``ResultManagement/Results``: a variable of ``JoiningSystemResultType``
  (data type ``ResultDataType``) named ``Result_<run id>`` (a browse name
  without ``/``, which browse paths use), its node id
  ``s=<station>/results/<ResultId>``; the newest
  :data:`KEPT_RESULTS` stay, the oldest go (a client reads the latest there);
- a ``JoiningSystemResultReadyEventType`` event from the joining system, its
  ``Result`` the same ``ResultDataType``, severity :data:`RESULT_SEVERITY`. The model
  marks the type abstract; IJT's own servers send it as it is, and so does this one.

Its alerts and a controller's alarms are conditions (:mod:`.alert_conditions`).

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
from datetime import UTC, datetime
from typing import Any

from asyncua import Server, ua
from asyncua.common.manage_nodes import delete_nodes
from asyncua.common.node import Node

from services.opcua.event_contents import base_fields, new_event_id, result_ready_fields
from services.opcua.event_delivery import SERVER, EventDelivery, type_chain
from services.opcua.nodeset_loading import IJT_BASE, MACHINERY_RESULT, node_id
from services.opcua.served_events import ServedEvent
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
RESULT_DATA_TYPE = 3008
#: a result-ready event's Severity (1 to 1000: information)
RESULT_SEVERITY = 100
#: the joining system's folder of Machinery's building blocks
BUILDING_BLOCKS = "MachineryBuildingBlocks"


def result_browse_name(run_id: int) -> str:
    """The browse name of a run's result in its station's Results folder."""
    return f"Result_{run_id}"


def cycle_browse_name(sync_id: int) -> str:
    """The browse name of a multi-spindle cycle's common result in the Results folder."""
    return f"Cycle_{sync_id}"


class JoiningSystem:
    """A station's joining system in the address space; its events through ``delivery``."""

    def __init__(
        self,
        station: str,
        node: Node,
        results: Node,
        delivery: EventDelivery,
        names: tuple[int, int, int],
        result_types: tuple[ua.NodeId, ...],
    ) -> None:
        self.station = station
        self.node = node
        self._results = results
        self._delivery = delivery
        self._names = names
        self._result_types = result_types
        #: the notifiers its events are reported to: itself, Machines, Server
        self.notifiers = (node.nodeid, delivery.machines, SERVER)
        self._kept: deque[Node] = deque()

    @classmethod
    async def create(cls, server: Server, station: str, delivery: EventDelivery) -> JoiningSystem:
        ours = await server.register_namespace(BOLTWATCH_NAMESPACE)
        ijt = await server.get_namespace_index(IJT_BASE)
        result_ns = await server.get_namespace_index(MACHINERY_RESULT)
        machines = server.get_node(delivery.machines)
        node = await machines.add_object(
            node_id(station, ours),
            ua.QualifiedName(station, ours),
            objecttype=node_id(JOINING_SYSTEM_TYPE, ijt),
        )
        await drop_placeholders(node)
        await share_building_blocks(node)
        await delivery.add_notifier(node)
        results = await node.get_child([f"{result_ns}:ResultManagement", f"{result_ns}:Results"])
        result_types = await type_chain(server, node_id(RESULT_READY_EVENT_TYPE, ijt))
        names = (ours, ijt, result_ns)
        LOG.info("joining system %s at %s", station, node.nodeid.to_string())
        return cls(station, node, results, delivery, names, result_types)

    async def result_management_method(self, name: str) -> Node:
        """A method of the joining system's ResultManagement (e.g. ``GetResultById``)."""
        _ours, _ijt, result_ns = self._names
        return await self.node.get_child([f"{result_ns}:ResultManagement", f"{result_ns}:{name}"])

    async def publish(self, result_id: str, browse_name: str, result: Any, message: str) -> None:
        """``result`` (a ``ua.ResultDataType``) into Results as ``browse_name``
        (:func:`result_browse_name`, :func:`cycle_browse_name`), then the result-ready event."""
        ours, ijt, result_ns = self._names
        variable = await add_typed_variable(
            self._results,
            node_id(f"{self.station}/results/{result_id}", ours),
            ua.QualifiedName(browse_name, ours),
            ua.Variant(result, ua.VariantType.ExtensionObject),
            node_id(RESULT_DATA_TYPE, result_ns),
            node_id(JOINING_SYSTEM_RESULT_TYPE, ijt),
        )
        self._kept.append(variable)
        while len(self._kept) > KEPT_RESULTS:
            await remove_child(
                self._results, self._kept.popleft(), node_id(ua.ObjectIds.HasComponent)
            )
        fields = base_fields(
            event_id=new_event_id(),
            types=self._result_types,
            source=(self.node.nodeid, self.station),
            time=datetime.now(UTC),
            message=message,
            severity=RESULT_SEVERITY,
        )
        fields.update(result_ready_fields(result_ns, result))
        await self._delivery.deliver(
            ServedEvent(types=self._result_types, fields=fields, notifiers=self.notifiers)
        )

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
