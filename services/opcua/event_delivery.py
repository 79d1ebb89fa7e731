"""The server's events to every monitored item that watches a notifier of theirs, and
ConditionRefresh.

OPC 10000-3 (4.7) and 10000-5 (8.3.2): every event of a server reaches a client
subscribed on the Server object; a notifier below it (``HasNotifier``) gives the events
of its part of the address space. The hierarchy here: Server
``HasNotifier`` Machinery's ``Machines`` folder ``HasNotifier`` each joining system, each
an event notifier (:meth:`EventDelivery.create`, :meth:`EventDelivery.add_notifier`).
Each :class:`~.served_events.ServedEvent` names the notifiers it is reported to (its
joining system, ``Machines``, Server).

asyncua 2.1 delivers an event to the monitored items of its emitting node only, compares
``OfType`` with the event's own type only (a subtype does not match), and selects a
field by the first name of its browse path. :class:`EventDelivery` therefore delivers
the server's events itself: for each subscription, each of its event monitored items
(not disabled) on one of the event's notifiers, the item's where clause and select
clauses applied by :mod:`.event_filter`, the fields put into the subscription's queue
as asyncua does (``enqueue_event``). What it reads of asyncua: the subscriptions of the
subscription service, and each subscription's monitored items (the monitored item
service's ``_monitored_items``: their node, attribute, mode, filter, queue size and
client handle). A where clause it cannot evaluate is logged once per monitored item and
the event not delivered to it.

It keeps the retained conditions (an event with a ``ConditionId`` and ``Retain`` true, the
last one of each condition; OPC 10000-9, 5.5.2) and answers ``ConditionRefresh`` and
``ConditionRefresh2`` (5.5.7, 5.5.8) in asyncua's place: a ``RefreshStartEvent`` to
every event monitored item of the subscription (or the one named), each retained
condition's last event (same EventId and Time) to the items that see it and whose where
clause it passes, a ``RefreshEndEvent``. A subscription of another session is refused
(``BadUserAccessDenied``), one without event items answers ``BadNothingToDo``.
"""

from __future__ import annotations

import asyncio
import logging
from datetime import UTC, datetime
from typing import Any

from asyncua import Server, ua
from asyncua.common.node import Node

from services.opcua.client_sessions import CALLER
from services.opcua.event_contents import base_fields, new_event_id
from services.opcua.event_filter import UnsupportedFilterError, selected, where_matches
from services.opcua.nodeset_loading import MACHINERY, node_id
from services.opcua.served_events import ServedEvent

LOG = logging.getLogger(__name__)

SERVER = node_id(ua.ObjectIds.Server)
MACHINES_FOLDER = 1001  # Machinery's Machines folder
REFRESH_START = node_id(ua.ObjectIds.RefreshStartEventType)
REFRESH_END = node_id(ua.ObjectIds.RefreshEndEventType)
EVENT_NOTIFIER = ua.AttributeIds.EventNotifier
HAS_NOTIFIER = node_id(ua.ObjectIds.HasNotifier)


async def type_chain(server: Server, type_id: ua.NodeId) -> tuple[ua.NodeId, ...]:
    """``type_id`` and its supertypes, up to BaseEventType (what ``OfType`` matches)."""
    chain = [type_id]
    node = server.get_node(type_id)
    while node.nodeid != node_id(ua.ObjectIds.BaseEventType):
        parents = await node.get_referenced_nodes(
            refs=ua.ObjectIds.HasSubtype, direction=ua.BrowseDirection.Inverse
        )
        if len(parents) != 1:
            raise ValueError(f"{type_id.to_string()}: not a subtype of BaseEventType")
        node = parents[0]
        chain.append(node.nodeid)
    return tuple(chain)


class EventDelivery:
    """The events of the server's joining systems, to the subscriptions that see them."""

    def __init__(
        self,
        server: Server,
        machines: ua.NodeId,
        refresh_types: tuple[tuple[ua.NodeId, ...], ...],
    ) -> None:
        self._subscriptions = server.iserver.subscription_service.subscriptions
        #: Machinery's Machines folder, the joining systems' notifier
        self.machines = machines
        self._refresh_start, self._refresh_end = refresh_types
        #: each retained condition's last event, by ConditionId
        self.retained: dict[ua.NodeId, ServedEvent] = {}
        self._said: set[tuple[int, int]] = set()  # monitored items whose filter was refused
        #: one delivery at a time: putting an event into a queue may let the loop run on
        #: (and a client act on it: acknowledge), and every subscription must see an event
        #: before it sees the next one
        self._one_at_a_time = asyncio.Lock()

    @classmethod
    async def create(cls, server: Server) -> EventDelivery:
        """Ready, and answering ConditionRefresh and ConditionRefresh2 of ``server``; Server
        ``HasNotifier`` Machines (with the models loaded)."""
        types = (await type_chain(server, REFRESH_START), await type_chain(server, REFRESH_END))
        machines = server.get_node(
            node_id(MACHINES_FOLDER, await server.get_namespace_index(MACHINERY))
        )
        await machines.set_event_notifier([ua.EventNotifier.SubscribeToEvents])
        await server.get_node(SERVER).add_reference(machines.nodeid, HAS_NOTIFIER, forward=True)
        delivery = cls(server, machines.nodeid, types)
        for method in (
            ua.ObjectIds.ConditionType_ConditionRefresh,
            ua.ObjectIds.ConditionType_ConditionRefresh2,
        ):
            server.link_method(server.get_node(node_id(method)), delivery.condition_refresh)
        return delivery

    async def add_notifier(self, system: Node) -> None:
        """Machines ``HasNotifier`` ``system`` (a joining system), an event notifier."""
        await system.set_event_notifier([ua.EventNotifier.SubscribeToEvents])
        await Node(system.session, self.machines).add_reference(system.nodeid, HAS_NOTIFIER)

    async def deliver(self, event: ServedEvent) -> None:
        """``event`` to every event monitored item on one of its notifiers whose where clause
        it passes; a condition's kept while retained. Events reach every subscription in the
        order they are delivered in."""
        async with self._one_at_a_time:
            await self._deliver(event)

    async def _deliver(self, event: ServedEvent) -> None:
        if event.condition_id is not None:
            retain = event.fields.get(((0, "Retain"),))
            if retain is not None and retain.Value:
                self.retained[event.condition_id] = event
            else:
                self.retained.pop(event.condition_id, None)
        for subscription in list(self._subscriptions.values()):
            for mid, item in _event_items(subscription):
                if item.read_value_id.NodeId in event.notifiers:
                    await self._to_item(subscription, mid, item, event, filtered=True)

    async def condition_refresh(self, _parent: ua.NodeId, *arguments: ua.Variant) -> Any:
        """ConditionRefresh(SubscriptionId) and ConditionRefresh2(SubscriptionId,
        MonitoredItemId)."""
        values: list[Any] = [getattr(argument, "Value", None) for argument in arguments]
        if not 1 <= len(values) <= 2 or not all(
            isinstance(value, int) and not isinstance(value, bool) for value in values
        ):
            return _status(ua.StatusCodes.BadInvalidArgument)
        subscription = self._subscriptions.get(values[0])
        if subscription is None:
            return _status(ua.StatusCodes.BadSubscriptionIdInvalid)
        caller = CALLER.get()
        if caller is not None and subscription.session_id != caller.session_id:
            return _status(ua.StatusCodes.BadUserAccessDenied)
        items = dict(_event_items(subscription))
        if len(values) == 2:
            if values[1] not in items:
                return _status(ua.StatusCodes.BadMonitoredItemIdInvalid)
            items = {values[1]: items[values[1]]}
        if not items:
            return _status(ua.StatusCodes.BadNothingToDo)
        async with self._one_at_a_time:
            await self._refresh(subscription, items)
        return []

    async def _refresh(self, subscription: Any, items: dict[int, Any]) -> None:
        for bracket in (self._refresh_start, None, self._refresh_end):
            if bracket is None:
                for event in list(self.retained.values()):
                    for mid, item in items.items():
                        if item.read_value_id.NodeId in event.notifiers:
                            await self._to_item(subscription, mid, item, event, filtered=True)
                continue
            marker = _refresh_event(bracket)  # one EventId for every copy
            for mid, item in items.items():
                await self._to_item(subscription, mid, item, marker, filtered=False)

    async def _to_item(
        self, subscription: Any, mid: int, item: Any, event: ServedEvent, filtered: bool
    ) -> None:
        event_filter = item.filter if isinstance(item.filter, ua.EventFilter) else ua.EventFilter()
        if filtered:
            try:
                if not where_matches(event_filter.WhereClause, event):
                    return
            except UnsupportedFilterError as err:
                key = (int(subscription.data.SubscriptionId), mid)
                if key not in self._said:
                    self._said.add(key)
                    LOG.warning(
                        "events not delivered to monitored item %d of subscription %d: its where "
                        "clause holds %s, which the server cannot evaluate",
                        mid,
                        key[0],
                        err,
                    )
                return
        fields = ua.EventFieldList(
            ClientHandle=item.client_handle,
            EventFields=selected(list(event_filter.SelectClauses or []), event),
        )
        await subscription.enqueue_event(mid, fields, item.queue_size)


def _status(code: int) -> ua.StatusCode:
    return ua.StatusCode(ua.UInt32(code))


def _event_items(subscription: Any) -> list[tuple[int, Any]]:
    """The subscription's event monitored items that are not disabled, by id."""
    items = subscription.monitored_item_srv._monitored_items  # asyncua has no public view
    return [
        (mid, item)
        for mid, item in list(items.items())
        if item.read_value_id is not None
        and item.read_value_id.AttributeId == EVENT_NOTIFIER
        and item.mode != ua.MonitoringMode.Disabled
    ]


def _refresh_event(types: tuple[ua.NodeId, ...]) -> ServedEvent:
    """A RefreshStartEvent or RefreshEndEvent of the Server object."""
    now = datetime.now(UTC)
    fields = base_fields(
        event_id=new_event_id(),
        types=types,
        source=(SERVER, "Server"),
        time=now,
        message="ConditionRefresh",
        severity=100,
    )
    return ServedEvent(types=types, fields=fields, notifiers=(SERVER,))
