"""The server's events as generic clients subscribe to them, and the alerts' conditions: a real
asyncua server on loopback (the models loaded, joining systems st1 and st2, the service's
event delivery and condition methods) and real asyncua clients, anonymous or logged in.

A result's event reaches a client subscribed on the Server object, on Machines and on its
joining system, once each, with a structure's sub-field selectable; a where clause's
OfType matches subtypes; a wear alert is a condition that an operator acknowledges and
confirms (on the instance or through the type's method), that ConditionRefresh returns
while it is retained, and whose acknowledgement is recorded with its user.

One server for the module (loading the models takes a few seconds). Needs the fetched
NodeSet2 files (``make opcua-nodesets``).
"""

from __future__ import annotations

import asyncio
import threading
from collections.abc import Iterator
from dataclasses import dataclass, field
from typing import Any

import pytest
from asyncua import Client, Server, ua
from asyncua.crypto.permission_rules import User, UserRole
from asyncua.server.user_managers import UserManager

from services.opcua.alert_conditions import ConditionMethods, StationConditions
from services.opcua.alert_events import alert_event, wear_cleared
from services.opcua.client_sessions import use_client_sessions
from services.opcua.event_delivery import EventDelivery
from services.opcua.joining_systems import JoiningSystem, result_browse_name
from services.opcua.nodeset_files import missing_files, nodeset_folder
from services.opcua.nodeset_loading import (
    IJT_BASE,
    MACHINERY,
    MACHINERY_RESULT,
    load_models,
    node_id,
)
from services.opcua.result_encoding import result_data
from services.opcua.result_values import result_values
from shared.contract import AlertAck, WearAlert
from tests.support import factories
from tests.support.live_recorder import free_port

if missing_files(nodeset_folder()):
    pytest.skip(
        "the OPC UA models are not fetched (`make opcua-nodesets` needs npm)",
        allow_module_level=True,
    )

OPERATOR, READER = "scada", "mes"
WAIT_S = 30.0  # the longest wait for a notification (publishing every 20 ms)
Op = ua.FilterOperator
SERVER_OBJECT = node_id(ua.ObjectIds.Server)
CONDITION_TYPE = node_id(ua.ObjectIds.ConditionType)
REFRESH = node_id(ua.ObjectIds.ConditionType_ConditionRefresh)
REFRESH_START = node_id(ua.ObjectIds.RefreshStartEventType)
REFRESH_END = node_id(ua.ObjectIds.RefreshEndEventType)
CONFIRM_TYPE_METHOD = node_id(ua.ObjectIds.AcknowledgeableConditionType_Confirm)


class _AnyPassword(UserManager):
    """A session's user by its name, anonymous without one (the password is not what is
    tested here); each one reads, as asyncua's users do."""

    def get_user(
        self, iserver: Any, username: Any = None, password: Any = None, certificate: Any = None
    ) -> User:
        return User(role=UserRole.User, name=username)


class _Received:
    """A client's event notifications: each one's fields, in the select clauses' order."""

    def __init__(self) -> None:
        self.fields: list[list[Any]] = []

    def event_notification(self, event: Any) -> None:
        self.fields.append([variant.Value for variant in event.event_fields])


@dataclass
class Served:
    loop: asyncio.AbstractEventLoop
    server: Server
    endpoint: str
    systems: dict[str, JoiningSystem]
    conditions: dict[str, StationConditions]
    recorded: list[AlertAck] = field(default_factory=list)
    names: dict[str, int] = field(default_factory=dict)

    def run(self, coroutine: Any) -> Any:
        return asyncio.run_coroutine_threadsafe(coroutine, self.loop).result()


@pytest.fixture(scope="module")
def served() -> Iterator[Served]:
    loop = asyncio.new_event_loop()
    thread = threading.Thread(target=loop.run_forever, name="opcua-server")
    thread.start()
    endpoint = f"opc.tcp://127.0.0.1:{free_port()}"
    recorded: list[AlertAck] = []

    async def record(ack: AlertAck) -> None:
        recorded.append(ack)

    async def start() -> Served:
        server = Server()
        await server.init()
        server.set_endpoint(endpoint)
        server.set_identity_tokens([ua.AnonymousIdentityToken, ua.UserNameIdentityToken])
        server.iserver.set_user_manager(_AnyPassword())
        use_client_sessions(server)
        await load_models(server, nodeset_folder())
        delivery = await EventDelivery.create(server)
        methods = ConditionMethods(server, frozenset({OPERATOR}), record)
        methods.link_type_methods()
        systems = {st: await JoiningSystem.create(server, st, delivery) for st in ("st1", "st2")}
        conditions = {
            st: await StationConditions.create(server, system, delivery, methods)
            for st, system in systems.items()
        }
        await server.start()
        names = {
            "result": await server.get_namespace_index(MACHINERY_RESULT),
            "ijt": await server.get_namespace_index(IJT_BASE),
            "machinery": await server.get_namespace_index(MACHINERY),
        }
        return Served(loop, server, endpoint, systems, conditions, recorded, names)

    serving = asyncio.run_coroutine_threadsafe(start(), loop).result()
    try:
        yield serving
        serving.run(serving.server.stop())
    finally:
        loop.call_soon_threadsafe(loop.stop)
        thread.join()
        loop.close()


def _path(*names: tuple[int, str] | str) -> ua.SimpleAttributeOperand:
    return ua.SimpleAttributeOperand(
        TypeDefinitionId=node_id(ua.ObjectIds.BaseEventType),
        BrowsePath=[
            ua.QualifiedName(name) if isinstance(name, str) else ua.QualifiedName(name[1], name[0])
            for name in names
        ],
        AttributeId=ua.AttributeIds.Value,
    )


def _of_type(type_id: ua.NodeId) -> ua.ContentFilter:
    operand = ua.LiteralOperand(Value=ua.Variant(type_id, ua.VariantType.NodeId))
    element = ua.ContentFilterElement(FilterOperator=Op.OfType, FilterOperands=[operand])
    return ua.ContentFilter(Elements=[element])


async def _client(served: Served, user: str | None = None) -> Client:
    client = Client(served.endpoint)
    if user is not None:
        client.set_user(user)
        client.set_password("any")
    await client.connect()
    return client


async def _subscribe(
    client: Client,
    node: ua.NodeId,
    select: list[ua.SimpleAttributeOperand],
    where: ua.ContentFilter,
) -> tuple[Any, _Received]:
    received = _Received()
    subscription = await client.create_subscription(20, received)
    event_filter = ua.EventFilter(SelectClauses=select, WhereClause=where)
    await subscription.subscribe_events(node, evfilter=event_filter)
    return subscription, received


async def _until(received: _Received, count: int) -> list[list[Any]]:
    """The notifications once ``count`` have come (AssertionError after WAIT_S)."""
    async with asyncio.timeout(WAIT_S):
        while len(received.fields) < count:
            await asyncio.sleep(0.01)
    return received.fields


def _result(served: Served, station: str, run_id: int, verdict: str = "OK") -> Any:
    result = factories.result(run_id, station=station, result=verdict)
    return served.systems[station].publish(
        f"{station}/{run_id}",
        result_browse_name(run_id),
        result_data(result_values(result)),
        f"{station}/{run_id}",
    )


def test_a_result_reaches_the_server_object_machines_and_its_joining_system_once_each(
    served: Served,
) -> None:
    """OPC 10000-5, 8.3.2: every event of the server from the Server object; Machines and
    each joining system give theirs. ``Result/ResultMetaData/ResultId`` and
    ``.../ResultEvaluation`` are selectable (sub-fields of the Result structure)."""
    result_ns = served.names["result"]
    select = [
        _path("SourceName"),
        _path((result_ns, "Result"), (result_ns, "ResultMetaData"), (result_ns, "ResultId")),
        _path((result_ns, "Result"), "ResultMetaData", "ResultEvaluation"),
        _path((result_ns, "Result"), "ResultMetaData", "NoSuchField"),
    ]
    everything = ua.ContentFilter()

    async def scenario() -> dict[str, list[list[Any]]]:
        client = await _client(served)
        machines = node_id(1001, served.names["machinery"])
        watched = {
            "server": SERVER_OBJECT,
            "machines": machines,
            "st1": served.systems["st1"].node.nodeid,
            "st2": served.systems["st2"].node.nodeid,
        }
        handlers = {
            name: (await _subscribe(client, node, select, everything))[1]
            for name, node in watched.items()
        }
        await _result(served, "st1", 7)
        await _result(served, "st2", 8, "NOK")
        await _result(served, "st1", 9)
        found = {
            "server": await _until(handlers["server"], 3),
            "machines": await _until(handlers["machines"], 3),
            "st1": await _until(handlers["st1"], 2),
            "st2": await _until(handlers["st2"], 1),
        }
        notifiers = [
            await client.get_node(start).get_referenced_nodes(
                refs=ua.ObjectIds.HasNotifier, direction=ua.BrowseDirection.Forward
            )
            for start in (SERVER_OBJECT, machines)
        ]
        found["notifiers"] = [[node.nodeid for node in nodes] for nodes in notifiers]
        await client.disconnect()
        return found

    found = served.run(scenario())
    st1_7, st2_8, st1_9 = (
        ["st1", "st1/7", 1, None],
        ["st2", "st2/8", 2, None],
        ["st1", "st1/9", 1, None],
    )
    assert found["server"] == found["machines"] == [st1_7, st2_8, st1_9]
    assert found["st1"] == [st1_7, st1_9]
    assert found["st2"] == [st2_8]
    machines_node = node_id(1001, served.names["machinery"])
    assert found["notifiers"] == [
        [machines_node],
        [served.systems["st1"].node.nodeid, served.systems["st2"].node.nodeid],
    ]


def test_of_type_matches_a_type_s_subtypes_and_a_filter_it_cannot_evaluate_gets_nothing(
    served: Served,
) -> None:
    """Machinery/Result's ResultReadyEventType is a supertype of IJT's result-ready event;
    AcknowledgeableConditionType of IJT's condition; a Cast is not evaluated."""
    result_ns, ijt = served.names["result"], served.names["ijt"]
    select = [_path("EventType"), _path("SourceName")]
    cast = ua.ContentFilter(
        Elements=[
            ua.ContentFilterElement(
                FilterOperator=Op.Cast,
                FilterOperands=[
                    ua.LiteralOperand(Value=ua.Variant(1)),
                    ua.LiteralOperand(Value=ua.Variant(node_id(ua.ObjectIds.String))),
                ],
            )
        ]
    )

    async def scenario() -> tuple[list[list[Any]], ...]:
        client = await _client(served)
        _, results = await _subscribe(
            client, SERVER_OBJECT, select, _of_type(node_id(1002, result_ns))
        )
        _, conditions = await _subscribe(
            client,
            SERVER_OBJECT,
            select,
            _of_type(node_id(ua.ObjectIds.AcknowledgeableConditionType)),
        )
        _, refused = await _subscribe(client, SERVER_OBJECT, select, cast)
        await served.conditions["st2"].report(
            alert_event(WearAlert("st2", 99, factories.T0, 600.0, 500.0, 3, None))
        )
        await _result(served, "st2", 20)
        found = (await _until(results, 1), await _until(conditions, 1), refused.fields)
        await client.disconnect()
        return found

    results, conditions, refused = served.run(scenario())
    assert results == [[node_id(1007, ijt), "st2"]]
    assert conditions == [[node_id(1020, ijt), "st2"]]
    assert refused == []


def test_a_wear_condition_is_acknowledged_confirmed_refreshed_and_recorded(served: Served) -> None:
    """An operator acknowledges the notification it saw (on the instance's method) and
    confirms through the type's method with the ConditionId; a reader may not; the
    condition is retained, and ConditionRefresh returns it, until it is off, acknowledged
    and confirmed; the acknowledgement and the confirmation are recorded with the user."""
    select = [
        _path("EventId"),
        _path("EventType"),
        ua.SimpleAttributeOperand(
            TypeDefinitionId=CONDITION_TYPE, AttributeId=ua.AttributeIds.NodeId
        ),
        _path("ConditionName"),
        _path("Retain"),
        _path("AckedState", "Id"),
        _path("ConfirmedState", "Id"),
        _path("Comment"),
    ]
    conditions = served.conditions["st1"]
    alert = alert_event(WearAlert("st1", 7, factories.T0, 512.3, 500.0, 88, None))
    # st1's conditions: OfType(AcknowledgeableConditionType) And SourceName = "st1" (another
    # test's st2 condition is retained too: ConditionRefresh on the Server gives every one)
    st1_conditions = _of_type(node_id(ua.ObjectIds.AcknowledgeableConditionType))
    st1_conditions.Elements = [
        ua.ContentFilterElement(
            FilterOperator=Op.And,
            FilterOperands=[ua.ElementOperand(Index=1), ua.ElementOperand(Index=2)],
        ),
        *st1_conditions.Elements,
        ua.ContentFilterElement(
            FilterOperator=Op.Equals,
            FilterOperands=[_path("SourceName"), ua.LiteralOperand(Value=ua.Variant("st1"))],
        ),
    ]

    async def call(client: Client, objects: tuple[ua.NodeId, ua.NodeId], *arguments: Any) -> str:
        request = ua.CallMethodRequest(
            ObjectId=objects[0], MethodId=objects[1], InputArguments=list(arguments)
        )
        [called] = await client.uaclient.call([request])
        return str(called.StatusCode.name)

    async def scenario() -> dict[str, Any]:
        operator, reader = await _client(served, OPERATOR), await _client(served, READER)
        subscription, received = await _subscribe(operator, SERVER_OBJECT, select, st1_conditions)
        await conditions.report(alert)
        [raised] = await _until(received, 1)
        event_id, condition_id = raised[0], raised[2]
        refresh = (CONDITION_TYPE, REFRESH)
        sub_id = ua.Variant(subscription.subscription_id, ua.VariantType.UInt32)
        found: dict[str, Any] = {"raised": raised, "refresh": await call(operator, refresh, sub_id)}
        found["refreshed"] = (await _until(received, 4))[1:4]
        acknowledge = (
            condition_id,
            (await operator.get_node(condition_id).get_child("0:Acknowledge")).nodeid,
        )
        comment = ua.Variant(
            ua.LocalizedText("tool changed at the next stop"), ua.VariantType.LocalizedText
        )
        found["by reader"] = await call(
            reader, acknowledge, ua.Variant(event_id, ua.VariantType.ByteString), comment
        )
        found["wrong id"] = await call(
            operator, acknowledge, ua.Variant(b"not an event", ua.VariantType.ByteString), comment
        )
        found["acknowledged"] = await call(
            operator, acknowledge, ua.Variant(event_id, ua.VariantType.ByteString), comment
        )
        found["again"] = await call(
            operator, acknowledge, ua.Variant(event_id, ua.VariantType.ByteString), comment
        )
        found["confirmed"] = await call(
            operator,
            (condition_id, CONFIRM_TYPE_METHOD),
            ua.Variant(event_id, ua.VariantType.ByteString),
            ua.Variant(ua.LocalizedText(""), ua.VariantType.LocalizedText),
        )
        found["states"] = [fields[4:7] for fields in (await _until(received, 6))[4:6]]
        found["read"] = await operator.get_node(condition_id).get_child(["0:AckedState", "0:Id"])
        found["read"] = await found["read"].read_value()
        await call(operator, refresh, sub_id)
        found["still"] = [fields[1] for fields in (await _until(received, 9))[6:9]]
        await conditions.report(wear_cleared("st1", 7, factories.T0 + 1, 0.0, 500.0))
        found["off"] = (await _until(received, 10))[9][4:7]
        await call(operator, refresh, sub_id)
        found["gone"] = [fields[1] for fields in (await _until(received, 12))[10:12]]
        await operator.disconnect()
        await reader.disconnect()
        return found

    found = served.run(scenario())
    event_id, _type, condition_id, name, retain, acked, confirmed, _comment = found["raised"]
    assert (name, retain, acked, confirmed) == ("Wear of tool 7", True, False, True)
    assert found["refresh"] == "Good"
    assert [fields[1] for fields in found["refreshed"]] == [REFRESH_START, _type, REFRESH_END]
    assert found["refreshed"][1][0] == event_id  # the condition's last notification as it was
    assert found["by reader"] == "BadUserAccessDenied"
    assert found["wrong id"] == "BadEventIdUnknown"
    assert (found["acknowledged"], found["again"]) == ("Good", "BadConditionBranchAlreadyAcked")
    assert found["confirmed"] == "Good"
    assert found["states"] == [[True, True, False], [True, True, True]]  # Retain, Acked, Confirmed
    assert found["read"] is True
    assert found["still"] == [REFRESH_START, _type, REFRESH_END]  # on: still retained
    assert found["off"] == [False, True, True]
    assert found["gone"] == [REFRESH_START, REFRESH_END]
    acknowledged, confirmed_record = served.recorded
    assert (acknowledged.action, acknowledged.user, acknowledged.condition) == (
        "acknowledged", OPERATOR, "wear/7"
    )  # fmt: skip
    assert acknowledged.comment == "tool changed at the next stop" and acknowledged.active
    assert (confirmed_record.action, confirmed_record.station) == ("confirmed", "st1")
    assert condition_id == node_id(
        "st1/conditions/wear/7", served.systems["st1"].node.nodeid.NamespaceIndex
    )


def test_condition_refresh_is_the_caller_s_own_subscription(served: Served) -> None:
    """Another session's subscription: BadUserAccessDenied; no such one:
    BadSubscriptionIdInvalid; one without event items: BadNothingToDo."""

    async def scenario() -> list[str]:
        owner, other = await _client(served), await _client(served)
        subscription, _ = await _subscribe(
            owner, SERVER_OBJECT, [_path("EventType")], ua.ContentFilter()
        )
        plain = await owner.create_subscription(20, _Received())
        statuses = []
        for client, sub_id in (
            (other, subscription.subscription_id),
            (owner, 999_999),
            (owner, plain.subscription_id),
            (owner, subscription.subscription_id),
        ):
            request = ua.CallMethodRequest(
                ObjectId=CONDITION_TYPE,
                MethodId=REFRESH,
                InputArguments=[ua.Variant(sub_id, ua.VariantType.UInt32)],
            )
            [called] = await client.uaclient.call([request])
            statuses.append(str(called.StatusCode.name))
        await owner.disconnect()
        await other.disconnect()
        return statuses

    assert served.run(scenario()) == [
        "BadUserAccessDenied",
        "BadSubscriptionIdInvalid",
        "BadNothingToDo",
        "Good",
    ]
