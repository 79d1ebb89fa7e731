"""ResultManagement's methods called by a real asyncua client of a real asyncua server on
loopback (the models loaded, a joining system st1), answering from a real SQLite results
store: GetLatestResult, GetResultIdListFiltered with the filters the store can answer and
those it refuses, ReleaseResultHandle, and the calls' argument checks.

One server for the module (loading the models takes a few seconds); each call is a
request of its own. Needs the fetched NodeSet2 files (``make opcua-nodesets``).
"""

from __future__ import annotations

import asyncio
import threading
from collections.abc import Iterator
from dataclasses import dataclass
from datetime import datetime
from pathlib import Path
from typing import Any

import pytest
from asyncua import Client, Server, ua
from asyncua.ua.ua_binary import struct_to_binary

from services.opcua.event_delivery import EventDelivery
from services.opcua.joining_systems import (
    BOLTWATCH_NAMESPACE,
    BUILDING_BLOCKS,
    JoiningSystem,
)
from services.opcua.nodeset_files import missing_files, nodeset_folder
from services.opcua.nodeset_loading import MACHINERY, MACHINERY_RESULT, load_models, node_id
from services.opcua.result_requests import (
    ERROR_STORE,
    ERROR_TOO_MANY,
    ERROR_UNKNOWN_HANDLE,
    ERROR_UNKNOWN_RESULT,
    latest_result,
    result_ids,
    result_management_methods,
)
from services.opcua.result_values import utc_time
from shared.contract import encode
from shared.recordings import classify
from shared.recordings.mcap import McapSink
from shared.results import ResultsQuery, ResultsStore, StoreTarget, store_target, stored_result
from tests.support import factories
from tests.support.live_recorder import free_port

if missing_files(nodeset_folder()):
    pytest.skip(
        "the OPC UA models are not fetched (`make opcua-nodesets` needs npm)",
        allow_module_level=True,
    )

SECOND_NS = 1_000_000_000
#: the ends of st1's runs 1 to 3 (run 1's half a microsecond past a whole one) and st2's 4
ENDED_NS = {
    1: factories.T0 + SECOND_NS + 500,
    2: factories.T0 + 2 * SECOND_NS,
    3: factories.T0 + 3 * SECOND_NS,
}
ST2_ENDED_NS = factories.T0 + 4 * SECOND_NS
SAMPLES = 12  # of run 3 in its recording
#: times beyond the nanoseconds since 1970 an int64 holds (1677 to 2262)
YEAR_9999, YEAR_1601 = datetime(9999, 12, 31), datetime(1601, 1, 2)
Op = ua.FilterOperator


def _store(folder: Path) -> StoreTarget:
    """st1's runs 1 (OK, part P1, program 1), 2 (NOK, P1, program 2) and 3 (OK, P2, program
    1, its recording with its samples), and st2's run 4, the newest of all."""
    recording = folder / "st1_run3.mcap"
    with McapSink(recording, {}, 3, factories.T0) as sink:
        for n in range(SAMPLES):
            sample = factories.sample(3, n)
            sink.write(classify("boltwatch/st1/samples", encode(sample), sample.time_ns))
    results = [
        (factories.result(1, time_ns=ENDED_NS[1], part_id="P1"), None),
        (factories.result(2, time_ns=ENDED_NS[2], part_id="P1", program_id=2, result="NOK"), None),
        (factories.result(3, time_ns=ENDED_NS[3], part_id="P2"), str(recording)),
        (factories.result(4, station="st2", time_ns=ST2_ENDED_NS), None),
    ]
    target = store_target(folder, None)
    with ResultsStore(target) as store:
        store.add([stored_result(result, "", path, "h", 1) for result, path in results])
    return target


@dataclass
class Served:
    """The server's loop (in its thread), its client, and the methods' node ids."""

    loop: asyncio.AbstractEventLoop
    client: Client
    management: ua.NodeId
    methods: dict[str, ua.NodeId]
    result_ns: int

    def call(self, method: str, *arguments: ua.Variant) -> ua.CallMethodResult:
        request = ua.CallMethodRequest(
            ObjectId=self.management, MethodId=self.methods[method], InputArguments=list(arguments)
        )
        called = self.client.uaclient.call([request])
        [result] = asyncio.run_coroutine_threadsafe(called, self.loop).result()
        return result

    def ids(self, content_filter: Any, ordered_by: Any = None, most: int = 0) -> list[str]:
        called = self.call(
            "GetResultIdListFiltered",
            ua.Variant(content_filter, ua.VariantType.ExtensionObject),
            ua.Variant(ordered_by, ua.VariantType.ExtensionObject, is_array=True),
            ua.Variant(most, ua.VariantType.UInt32),
            ua.Variant(0, ua.VariantType.Int32),
        )
        assert called.StatusCode.is_good(), called.StatusCode
        handle, identifiers, error = (output.Value for output in called.OutputArguments)
        assert (handle, error) == (0, 0)
        return list(identifiers or [])

    def field(self, *names: str) -> ua.SimpleAttributeOperand:
        return ua.SimpleAttributeOperand(
            BrowsePath=[ua.QualifiedName(name, self.result_ns) for name in names],
            AttributeId=ua.AttributeIds.Value,
        )


async def _start(target: StoreTarget, endpoint: str) -> tuple[Server, Served]:
    server = Server()
    await server.init()
    server.set_endpoint(endpoint)
    await load_models(server, nodeset_folder())
    result_ns = await server.get_namespace_index(MACHINERY_RESULT)
    system = await JoiningSystem.create(server, "st1", await EventDelivery.create(server))
    nodes = {}
    for name, callback in result_management_methods(target, "st1", result_ns).items():
        nodes[name] = await system.result_management_method(name)
        server.link_method(nodes[name], callback)
    await server.start()
    client = Client(endpoint)
    await client.connect()
    parent = await nodes["GetLatestResult"].get_parent()
    assert parent is not None
    management = parent.nodeid
    methods = {name: node.nodeid for name, node in nodes.items()}
    return server, Served(asyncio.get_running_loop(), client, management, methods, result_ns)


@pytest.fixture(scope="module")
def served(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Served]:
    target = _store(tmp_path_factory.mktemp("store"))
    loop = asyncio.new_event_loop()
    thread = threading.Thread(target=loop.run_forever, name="opcua-server")
    thread.start()
    started = asyncio.run_coroutine_threadsafe(
        _start(target, f"opc.tcp://127.0.0.1:{free_port()}"), loop
    )
    try:
        server, serving = started.result()
        yield serving
        asyncio.run_coroutine_threadsafe(serving.client.disconnect(), loop).result()
        asyncio.run_coroutine_threadsafe(server.stop(), loop).result()
    finally:
        loop.call_soon_threadsafe(loop.stop)
        thread.join()
        loop.close()


def _on_the_wire(*names: Any) -> ua.ExtensionObject:
    """A RelativePath as a client sends it (asyncua has no ExtensionObject encoding of its
    own for it)."""
    path = ua.RelativePath(Elements=[ua.RelativePathElement(TargetName=name) for name in names])
    encoding = ua.NodeId(ua.Int32(ua.ObjectIds.RelativePath_Encoding_DefaultBinary))
    return ua.ExtensionObject(TypeId=encoding, Body=ua.ByteString(struct_to_binary(path)))


def _filter(*elements: tuple[Any, list[Any]]) -> ua.ContentFilter:
    return ua.ContentFilter(
        Elements=[
            ua.ContentFilterElement(FilterOperator=operator, FilterOperands=operands)
            for operator, operands in elements
        ]
    )


def _literal(value: Any, kind: ua.VariantType = ua.VariantType.String) -> ua.LiteralOperand:
    return ua.LiteralOperand(Value=ua.Variant(value, kind))


def _created(run: int) -> ua.LiteralOperand:
    """Run ``run``'s CreationTime as the server sends it (whole microseconds)."""
    return _at(utc_time(ENDED_NS[run]))


def _at(when: datetime) -> ua.LiteralOperand:
    return _literal(when, ua.VariantType.DateTime)


def test_the_latest_result_is_the_stations_newest_with_its_trace(served: Served) -> None:
    called = served.call("GetLatestResult", ua.Variant(0, ua.VariantType.Int32))
    handle, result, error = (output.Value for output in called.OutputArguments)
    assert (handle, error) == (0, 0)
    assert result.ResultMetaData.ResultId == "st1/3"  # st2's run 4 is newer: another station's
    [step] = result.ResultContent[0].Value.Trace.StepTraces
    assert step.NumberOfTracePoints == SAMPLES


def test_an_empty_store_has_no_latest_result_and_a_missing_one_is_an_error(
    tmp_path: Path,
) -> None:
    empty = store_target(tmp_path, None)
    ResultsStore(empty).close()
    assert [output.Value for output in latest_result(empty, "st1")] == [
        0,
        None,
        ERROR_UNKNOWN_RESULT,
    ]
    missing = store_target(tmp_path / "none", None)
    assert latest_result(missing, "st1")[2].Value == ERROR_STORE


#: filters (their elements, a field by its name in ResultMetaData) and the ids they match
FILTERS = {
    "empty": ((), ["st1/3", "st1/2", "st1/1"]),
    "NotOK": (((Op.Equals, ["ResultEvaluation", _literal(2, ua.VariantType.Int32)]),), ["st1/2"]),
    "OK": (
        ((Op.Equals, ["ResultEvaluation", _literal(1, ua.VariantType.Int32)]),),
        ["st1/3", "st1/1"],
    ),
    "NotDecidable": (((Op.Equals, ["ResultEvaluation", _literal(3, ua.VariantType.Int32)]),), []),
    "part-and-program": (
        (
            (Op.And, [ua.ElementOperand(1), ua.ElementOperand(2)]),
            (Op.Equals, ["PartId", _literal("P1")]),
            (Op.Equals, [_literal("2"), "InternalRecipeId"]),
        ),
        ["st1/2"],
    ),
    "result-id": (((Op.Equals, ["ResultId", _literal("st1/2")]),), ["st1/2"]),
    "another-station-s-id": (((Op.Equals, ["ResultId", _literal("st2/4")]),), []),
    "since": (((Op.GreaterThanOrEqual, ["CreationTime", _created(2)]),), ["st1/3", "st1/2"]),
    # run 1 ended 500 ns past its CreationTime's microsecond: it is that microsecond
    "after": (((Op.GreaterThan, ["CreationTime", _created(1)]),), ["st1/3", "st1/2"]),
    "until": (((Op.LessThanOrEqual, ["CreationTime", _created(1)]),), ["st1/1"]),
    "at": (((Op.Equals, ["CreationTime", _created(1)]),), ["st1/1"]),
    "literal-first": (((Op.LessThan, [_created(2), "CreationTime"]),), ["st1/3"]),
    "between": (((Op.Between, ["CreationTime", _created(1), _created(2)]),), ["st1/2", "st1/1"]),
    # beyond an int64's nanoseconds: no bound, or no result
    "until-9999": (
        ((Op.LessThan, ["CreationTime", _at(YEAR_9999)]),),
        ["st1/3", "st1/2", "st1/1"],
    ),
    "after-9999": (
        ((Op.GreaterThan, ["CreationTime", _at(YEAR_9999)]),),
        [],
    ),
    "since-1601": (
        ((Op.GreaterThanOrEqual, ["CreationTime", _at(YEAR_1601)]),),
        ["st1/3", "st1/2", "st1/1"],
    ),
    "at-1601": (((Op.Equals, ["CreationTime", _at(YEAR_1601)]),), []),
    "an-empty-range": (
        (
            (Op.And, [ua.ElementOperand(1), ua.ElementOperand(2)]),
            (Op.LessThan, ["CreationTime", _created(1)]),
            (Op.GreaterThan, ["CreationTime", _created(3)]),
        ),
        [],
    ),
}


def test_the_ids_a_filter_matches_are_the_stations_newest_first(served: Served) -> None:
    """A field is named by its path in ResultType (``ResultMetaData/<field>``)."""
    for name, (elements, expected) in FILTERS.items():
        resolved = [
            (op, [served.field("ResultMetaData", o) if isinstance(o, str) else o for o in operands])
            for op, operands in elements
        ]
        assert served.ids(_filter(*resolved)) == expected, name


def test_the_event_s_paths_order_and_max_results(served: Served) -> None:
    part = served.field("Result", "ResultMetaData", "PartId")
    assert served.ids(_filter((Op.Equals, [part, _literal("P2")]))) == ["st1/3"]
    assert served.ids(None, most=2) == ["st1/3", "st1/2"]
    by_time = _on_the_wire(
        *(ua.QualifiedName(name, served.result_ns) for name in ("ResultMetaData", "CreationTime"))
    )
    assert served.ids(None, [by_time], most=2) == ["st1/1", "st1/2"]


def _refused_with(served: Served, content_filter: Any, ordered_by: Any = None) -> list[int]:
    called = served.call(
        "GetResultIdListFiltered",
        ua.Variant(content_filter, ua.VariantType.ExtensionObject),
        ua.Variant(ordered_by, ua.VariantType.ExtensionObject, is_array=True),
        ua.Variant(0, ua.VariantType.UInt32),
        ua.Variant(0, ua.VariantType.Int32),
    )
    assert called.StatusCode.value == ua.StatusCodes.BadInvalidArgument
    return [status.value for status in called.InputArgumentResults]


def test_a_filter_the_store_cannot_answer_is_refused_with_its_reason(served: Served) -> None:
    part, good = served.field("ResultMetaData", "PartId"), ua.StatusCodes.Good
    one = _literal("P1")
    refusals = {
        ua.StatusCodes.BadFilterOperatorUnsupported: (
            (Op.Or, [ua.ElementOperand(1), ua.ElementOperand(2)]),
            (Op.Equals, [part, one]),
            (Op.Equals, [part, _literal("P2")]),
        ),
        ua.StatusCodes.BadNotSupported: (
            (Op.Equals, [served.field("ResultMetaData", "SequenceNumber"), _literal("1")]),
        ),
        ua.StatusCodes.BadFilterOperandInvalid: (
            (Op.Equals, [served.field("ResultMetaData", "CreationTime"), one]),
        ),
        ua.StatusCodes.BadFilterOperandCountMismatch: ((Op.Equals, [part]),),
        ua.StatusCodes.BadFilterElementInvalid: (
            (Op.And, [ua.ElementOperand(0), ua.ElementOperand(0)]),
        ),
    }
    for status, elements in refusals.items():
        assert _refused_with(served, _filter(*elements)) == [status, good, good, good]
    assert _refused_with(served, _filter((Op.GreaterThan, [part, one])))[0] == (
        ua.StatusCodes.BadNotSupported  # PartId is compared by Equals only
    )
    by_part = _on_the_wire(*part.BrowsePath)
    assert _refused_with(served, None, [by_part]) == [
        good,
        ua.StatusCodes.BadNotSupported,
        good,
        good,
    ]


def test_more_ids_than_one_answer_holds_give_the_first_ones_and_an_error(tmp_path: Path) -> None:
    target = _store(tmp_path)
    query = ResultsQuery(stations=["st1"], limit=None)
    assert [output.Value for output in result_ids(target, "st1", query, 0, most=2)] == [
        0,
        ["st1/3", "st1/2"],
        ERROR_TOO_MANY,
    ]
    assert result_ids(target, "st1", query, 2, most=2)[2].Value == 0  # no more were asked


def test_handle_0_is_released_and_arguments_are_checked(served: Served) -> None:
    def error(handle: int) -> int:
        called = served.call("ReleaseResultHandle", ua.Variant(handle, ua.VariantType.UInt32))
        [output] = called.OutputArguments
        return int(output.Value)

    assert (error(0), error(5)) == (0, ERROR_UNKNOWN_HANDLE)
    missing = served.call("GetLatestResult")
    assert missing.StatusCode.value == ua.StatusCodes.BadArgumentsMissing
    zero = ua.Variant(0, ua.VariantType.Int32)
    too_many = served.call("GetLatestResult", zero, zero)
    assert too_many.StatusCode.value == ua.StatusCodes.BadTooManyArguments
    mistyped = served.call("GetResultById", zero, zero)  # a ResultId is text
    assert mistyped.StatusCode.value == ua.StatusCodes.BadInvalidArgument
    assert [status.value for status in mistyped.InputArgumentResults] == [
        ua.StatusCodes.BadTypeMismatch,
        ua.StatusCodes.Good,
    ]
    by_id = served.call("GetResultById", ua.Variant("st1/2", ua.VariantType.String), zero)
    assert by_id.OutputArguments[1].Value.ResultMetaData.ResultId == "st1/2"


def test_an_id_the_server_never_gives_is_unknown_to_both_methods(served: Served) -> None:
    """Not digits, a sign, a leading zero, beyond an int64 (more digits than int() reads):
    no result of either method."""
    result_id = served.field("ResultMetaData", "ResultId")
    zero = ua.Variant(0, ua.VariantType.Int32)
    odd = ("--5", "²", "-5", "02", "9223372036854775808", "1" * 5000)
    for text in (f"st1/{run}" for run in odd):
        by_id = served.call("GetResultById", ua.Variant(text, ua.VariantType.String), zero)
        assert by_id.StatusCode.is_good(), (text, by_id.StatusCode)
        assert by_id.OutputArguments[2].Value == ERROR_UNKNOWN_RESULT, text
        assert served.ids(_filter((Op.Equals, [result_id, _literal(text)]))) == [], text


def test_the_building_blocks_result_management_is_the_joining_system_s(served: Served) -> None:
    """MachineryBuildingBlocks refers to the joining system's own ResultManagement and
    Identification (in the model one object, referenced twice): a client that finds
    ResultManagement through the building blocks calls the same methods."""

    async def through_blocks() -> tuple[list[ua.NodeId], list[ua.NodeId], ua.CallMethodResult]:
        client = served.client
        ours = await client.get_namespace_index(BOLTWATCH_NAMESPACE)
        di = await client.get_namespace_index("http://opcfoundation.org/UA/DI/")
        system = client.get_node(node_id("st1", ours))
        machinery = await client.get_namespace_index(MACHINERY)
        blocks = f"{machinery}:{BUILDING_BLOCKS}"
        pairs = [
            (f"{served.result_ns}:ResultManagement",),
            (f"{di}:Identification",),
            (f"{served.result_ns}:ResultManagement", f"{served.result_ns}:GetLatestResult"),
        ]
        own = [(await system.get_child(list(path))).nodeid for path in pairs]
        shared = [(await system.get_child([blocks, *path])).nodeid for path in pairs]
        request = ua.CallMethodRequest(
            ObjectId=shared[0],
            MethodId=shared[2],
            InputArguments=[ua.Variant(0, ua.VariantType.Int32)],
        )
        [called] = await client.uaclient.call([request])
        return own, shared, called

    own, shared, called = asyncio.run_coroutine_threadsafe(through_blocks(), served.loop).result()
    assert shared == own
    assert called.StatusCode.is_good(), called.StatusCode
    _handle, result, error = (output.Value for output in called.OutputArguments)
    assert (error, result.ResultMetaData.ResultId) == (0, "st1/3")
