"""A station's alerts as conditions of its joining system, which a client acknowledges.

Each alert source (:mod:`.condition_states`: a tool's wear, a program's quality kind, a
controller's alarm code) is an instance of IJT Base's ``JoiningSystemConditionType``,
made at its first alert (with the type's optional children: ``ConfirmedState``,
``Confirm``, ``JoiningSystemEventContent``...): a component of the joining system
named ``Condition_<key>`` (``Condition_wear_7``), its node id
``s=<station>/conditions/<key>`` (the ``ConditionId``), and ``HasCondition`` from the
joining system to it (OPC 10000-9, 5.12). Each change of its state is an event of the
condition's type from the joining system (:class:`~.event_delivery.EventDelivery`: to
a client subscribed on the joining system, ``Machines`` or the Server object, and kept
for ``ConditionRefresh`` while ``Retain`` is true), and is written into the condition's
variables (a client reads the state there too).

The condition's methods, on the instance and on the type (a client may call the type's
``Acknowledge`` with the ``ConditionId`` as the object, 5.7.3): ``Acknowledge``,
``Confirm`` and ``AddComment`` (``EventId``, ``Comment``), by a session whose user is an
``operator`` of the users file (:mod:`.users_file`; anyone else: ``BadUserAccessDenied``).
Each one done is recorded (:class:`~shared.contract.AlertAck`: who, when, which
condition, the comment) through the ``record`` callback the service gives (zenoh's
``boltwatch/<st>/alert/ack``, which the line's recorder records, and the log).
``Enable`` and ``Disable`` answer ``BadNotSupported``: a line's alert is not switched off
from OPC UA (the line's page and ``boltwatch status`` show every alert).
"""

from __future__ import annotations

import asyncio
import logging
import time
from collections.abc import Awaitable, Callable, Sequence
from dataclasses import dataclass, field
from datetime import UTC, datetime
from typing import Any

from asyncua import Server, ua
from asyncua.common.node import Node

from services.opcua.alert_events import AlertEvent
from services.opcua.client_sessions import CALLER
from services.opcua.condition_states import Action, ConditionMethodError, ConditionState, Said
from services.opcua.event_contents import (
    base_fields,
    condition_fields,
    joining_content_fields,
    new_event_id,
)
from services.opcua.event_delivery import EventDelivery, type_chain
from services.opcua.joining_systems import JoiningSystem
from services.opcua.nodeset_loading import IJT_BASE, node_id
from services.opcua.result_values import JOINING_TECHNOLOGY, utc_time
from services.opcua.served_events import FieldPath, ServedEvent
from shared.contract import AlertAck

LOG = logging.getLogger(__name__)

#: IJT Base's JoiningSystemConditionType (numeric id in its namespace)
JOINING_SYSTEM_CONDITION_TYPE = 1020
#: the condition methods by their type's method (numeric ids of namespace 0), and what
#: each does
ACTIONS: dict[int, Action] = {
    ua.ObjectIds.AcknowledgeableConditionType_Acknowledge: "acknowledged",
    ua.ObjectIds.AcknowledgeableConditionType_Confirm: "confirmed",
    ua.ObjectIds.ConditionType_AddComment: "commented",
}
NOT_SUPPORTED = (ua.ObjectIds.ConditionType_Enable, ua.ObjectIds.ConditionType_Disable)
#: a method's browse name on the instance -> the type's method
INSTANCE_METHODS = {
    "Acknowledge": ua.ObjectIds.AcknowledgeableConditionType_Acknowledge,
    "Confirm": ua.ObjectIds.AcknowledgeableConditionType_Confirm,
    "AddComment": ua.ObjectIds.ConditionType_AddComment,
    "Enable": ua.ObjectIds.ConditionType_Enable,
    "Disable": ua.ObjectIds.ConditionType_Disable,
}

Record = Callable[[AlertAck], Awaitable[None]]


@dataclass
class _Condition:
    state: ConditionState
    node: Node
    variables: dict[FieldPath, Node | None] = field(default_factory=dict)
    transitions: dict[str, datetime] = field(default_factory=dict)


class StationConditions:
    """The conditions of one station's joining system."""

    def __init__(
        self,
        system: JoiningSystem,
        delivery: EventDelivery,
        methods: ConditionMethods,
        types: tuple[ua.NodeId, ...],
        namespaces: tuple[int, int],
    ) -> None:
        self.station = system.station
        self._system = system
        self._delivery = delivery
        self._methods = methods
        self._types = types
        self._ours, self._ijt = namespaces
        self._conditions: dict[str, _Condition] = {}
        self._by_node: dict[ua.NodeId, _Condition] = {}
        #: one change at a time: its notification goes out before the next change's
        self._changing = asyncio.Lock()

    @classmethod
    async def create(
        cls,
        server: Server,
        system: JoiningSystem,
        delivery: EventDelivery,
        methods: ConditionMethods,
    ) -> StationConditions:
        """The station's conditions (none until its first alert), whose methods ``methods``
        answers."""
        ijt = await server.get_namespace_index(IJT_BASE)
        types = await type_chain(server, node_id(JOINING_SYSTEM_CONDITION_TYPE, ijt))
        ours = system.node.nodeid.NamespaceIndex
        conditions = cls(system, delivery, methods, types, (ours, ijt))
        methods.stations.append(conditions)
        return conditions

    def holds(self, condition_id: ua.NodeId) -> bool:
        return condition_id in self._by_node

    def active_keys(self) -> list[str]:
        """The keys of the conditions whose alert is on."""
        return [key for key, held in self._conditions.items() if held.state.active]

    async def report(self, alert: AlertEvent) -> None:
        """The alert into its condition (made at its first alert); an event when its state
        changed (an alert that goes off while off changes nothing)."""
        async with self._changing:
            await self._report(alert)

    async def _report(self, alert: AlertEvent) -> None:
        held = self._conditions.get(alert.key)
        if held is None:
            if not alert.active:
                return  # off, and never on since the server started: nothing to say
            held = await self._make(alert)
        said = Said(alert.time_ns, alert.text, alert.severity, alert.code, alert.condition_class)
        before = (held.state.acked, held.state.confirmed)
        if alert.active:
            held.state.raised(said)
        elif not held.state.cleared(said):
            return
        self._transitions(held, before)
        await self._notify(held)

    async def act(
        self, condition_id: ua.NodeId, action: Action, event_id: bytes, comment: str, who: Any
    ) -> AlertAck:
        """Acknowledge, Confirm or AddComment of ``who`` (a session); its record.
        :class:`~.condition_states.ConditionMethodError` when refused."""
        held = self._by_node[condition_id]
        user = str(getattr(who, "user_name", "") or "")
        async with self._changing:
            before = (held.state.acked, held.state.confirmed)
            held.state.act(action, event_id, comment, user)
            self._transitions(held, before)
            await self._notify(held)
        return AlertAck(
            station=self.station,
            time_ns=time.time_ns(),
            action=action,
            source=held.state.source,
            condition=held.state.key,
            condition_name=held.state.name,
            alert_time_ns=held.state.time_ns,
            active=held.state.active,
            user=user,
            client=str(getattr(who, "client_uri", "") or ""),
            comment=comment,
        )

    async def _make(self, alert: AlertEvent) -> _Condition:
        system = self._system.node
        browse_name = "Condition_" + alert.key.replace("/", "_")
        node = await system.add_object(
            node_id(f"{self.station}/conditions/{alert.key}", self._ours),
            ua.QualifiedName(browse_name, self._ours),
            objecttype=self._types[0],
            instantiate_optional=True,
        )
        await system.add_reference(node.nodeid, node_id(ua.ObjectIds.HasCondition), forward=True)
        await self._methods.link_instance(node)
        held = _Condition(ConditionState(alert.key, alert.source, alert.name), node)
        self._conditions[alert.key] = held
        self._by_node[node.nodeid] = held
        LOG.info("%s: condition %s at %s", self.station, alert.name, node.nodeid.to_string())
        return held

    @staticmethod
    def _transitions(held: _Condition, before: tuple[bool, bool]) -> None:
        now = datetime.now(UTC)
        if before[0] != held.state.acked or "AckedState" not in held.transitions:
            held.transitions["AckedState"] = now
        if before[1] != held.state.confirmed or "ConfirmedState" not in held.transitions:
            held.transitions["ConfirmedState"] = now

    async def _notify(self, held: _Condition) -> None:
        """The condition's current state as an event, and into its variables."""
        state = held.state
        event_id = new_event_id()
        class_id, class_name = state.condition_class
        fields = base_fields(
            event_id=event_id,
            types=self._types,
            source=(self._system.node.nodeid, self.station),
            time=utc_time(state.time_ns),
            message=state.message,
            severity=state.severity,
            condition_class=(node_id(class_id, self._ijt), class_name),
        )
        fields.update(condition_fields(state, datetime.now(UTC), held.transitions))
        fields.update(
            joining_content_fields(self._ijt, state.code, state.message, JOINING_TECHNOLOGY)
        )
        state.notified(event_id)
        await self._write(held, fields)
        await self._delivery.deliver(
            ServedEvent(
                types=self._types,
                fields=fields,
                condition_id=held.node.nodeid,
                notifiers=self._system.notifiers,
            )
        )

    async def _write(self, held: _Condition, fields: dict[FieldPath, ua.Variant]) -> None:
        """Each field into the condition's variable of the same browse path (where it has
        one)."""
        for path, value in fields.items():
            if value.Value is None:
                continue
            if path not in held.variables:
                try:
                    held.variables[path] = await held.node.get_child(
                        [f"{ns}:{name}" for ns, name in path]
                    )
                except ua.UaError:
                    held.variables[path] = None
            variable = held.variables[path]
            if variable is not None:
                await variable.write_value(value)


class ConditionMethods:
    """Acknowledge, Confirm, AddComment (and Enable, Disable: not supported) of every
    station's conditions, on the type's methods and each instance's."""

    def __init__(self, server: Server, operators: frozenset[str], record: Record) -> None:
        self._server = server
        self._operators = operators
        self._record = record
        self.stations: list[StationConditions] = []

    def link_type_methods(self) -> None:
        """The type's methods (called with a ConditionId as the object)."""
        for method in (*ACTIONS, *NOT_SUPPORTED):
            node = self._server.get_node(node_id(method))
            self._server.link_method(node, self._callback(method))

    async def link_instance(self, condition: Node) -> None:
        """The methods of a condition instance."""
        for child in await condition.get_children(nodeclassmask=ua.NodeClass.Method):
            method = INSTANCE_METHODS.get(str((await child.read_browse_name()).Name))
            if method is not None:
                self._server.link_method(child, self._callback(method))

    def _callback(self, method: int) -> Callable[..., Awaitable[Any]]:
        action = ACTIONS.get(method)

        async def call(parent: ua.NodeId, *arguments: ua.Variant) -> Any:
            if action is None:
                return ua.StatusCode(ua.UInt32(ua.StatusCodes.BadNotSupported))
            return await self._act(action, parent, arguments)

        return call

    async def _act(self, action: Action, parent: ua.NodeId, arguments: Sequence[Any]) -> Any:
        if len(arguments) < 2:
            return _status(ua.StatusCodes.BadArgumentsMissing)
        if len(arguments) > 2:
            return _status(ua.StatusCodes.BadTooManyArguments)
        event_id, comment = (getattr(argument, "Value", argument) for argument in arguments)
        if not isinstance(event_id, bytes) or not isinstance(comment, ua.LocalizedText | None):
            return _status(ua.StatusCodes.BadInvalidArgument)
        station = next((s for s in self.stations if s.holds(parent)), None)
        if station is None:
            return _status(ua.StatusCodes.BadNodeIdUnknown)  # not one of the conditions
        caller = CALLER.get()
        user = caller.user_name if caller is not None else ""
        if user not in self._operators:
            LOG.warning(
                "OPC UA user %r may not act on conditions (%s refused): not an operator",
                user or "anonymous",
                action,
            )
            return _status(ua.StatusCodes.BadUserAccessDenied)
        text = (comment.Text or "") if comment is not None else ""
        try:
            record = await station.act(parent, action, event_id, text, caller)
        except ConditionMethodError as err:
            return _status(getattr(ua.StatusCodes, err.status))
        await self._record(record)
        return []


def _status(code: int) -> ua.StatusCode:
    return ua.StatusCode(ua.UInt32(code))
