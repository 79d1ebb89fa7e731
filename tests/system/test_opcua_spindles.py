"""A multi-spindle station's results over OPC UA, as IJT models a synchronised result, read
by a client of another implementation (node-opcua).

``boltwatch serve opcua`` serves the station of a real ``boltwatch up --spindles 2 --runs
2`` (router, acquisition with its predictor, a rig per spindle on a CAN bus, recorder with
its results store). A node-opcua client subscribed to the Server object's events before
the first run receives, per cycle, each spindle's result (a SINGLE_RESULT whose
``ResultCounters`` give its SPINDLE_NUMBER) and the cycle's own result: Classification
SYNC_RESULT, TOTAL_NUMBER_OF_SPINDLES 2, evaluation OK exactly when every spindle's is, and
in its ``ResultContent`` a reference to each spindle's result (its ResultId, evaluation and
spindle number), the same results the results store holds; GetResultById of the cycle's
ResultId gives the same result from the results store.
"""

from __future__ import annotations

import asyncio
from collections import defaultdict
from pathlib import Path
from typing import Any

import pytest
from asyncua import Client, Server, ua
from asyncua.crypto.security_policies import SecurityPolicyBasic256Sha256
from asyncua.crypto.uacrypto import CertProperties

from services.opcua.cycle_values import cycle_result_id
from services.opcua.joining_systems import BOLTWATCH_NAMESPACE
from services.opcua.nodeset_files import nodeset_folder
from services.opcua.nodeset_loading import MACHINERY_RESULT, load_models, node_id
from services.opcua.result_values import result_id
from shared.results import ResultsQuery, ResultsStore, store_target
from tests.support.live_recorder import free_port
from tests.support.opcua_certificates import (
    OpcuaCertificates,
    client_uri,
    make_opcua_certificates,
)
from tests.support.opcua_client import lines_of, start_client
from tests.support.opcua_line import (
    PASSWORD,
    USER,
    needs_node_opcua,
    secure_client_options,
    serve_secure_opcua,
    wait_subscribed,
)
from tests.support.station_files import write_station
from tests.support.station_up import run_up

pytestmark = pytest.mark.system

CYCLES, SPINDLES = 2, 2
CLIENT_TIMEOUT_S = 90
SINGLE_RESULT, SYNC_RESULT = 1, 2
SPINDLE_NUMBER, TOTAL_NUMBER_OF_SPINDLES = 7, 9
EVALUATION = {"OK": 1, "NOK": 2}


def _counters(counters: list[dict[str, Any]] | None) -> dict[int, int]:
    """ResultCounters as {CounterType: CounterValue}."""
    return {counter["counterType"]: counter["counterValue"] for counter in counters or []}


async def _references(
    endpoint: str, certificates: OpcuaCertificates, cycles: list[str]
) -> dict[str, list[tuple[str, int, int, list[tuple[int, int]]]]]:
    """Each cycle's references as asyncua's client reads them from the Results folder
    (ResultId, Classification, ResultEvaluation, counters; GetResultById gives the same
    result from the results store), decoded with the models' classes
    (the classes asyncua's client builds from the server's DataTypeDefinitions misread it:
    NotEnoughData); node-opcua 2.186 cannot decode a JoiningResultMetaDataType with
    ResultCounters (docs/how-to/opcua.md, interoperability note)."""
    certificate, key = certificates.clients["client"]
    client = Client(endpoint, timeout=30)
    client.application_uri = client_uri("client")
    client.set_user(USER)
    client.set_password(PASSWORD)
    await client.set_security(
        SecurityPolicyBasic256Sha256,
        certificate=str(certificate),
        private_key=CertProperties(key, extension="pem"),
        server_certificate=str(certificates.server_certificate),
        mode=ua.MessageSecurityMode.SignAndEncrypt,
    )
    found = {}
    models = Server()  # the models' classes, as the server has them, for the decoder
    await models.init()
    await load_models(models, nodeset_folder())
    async with client:
        ours = await client.get_namespace_index(BOLTWATCH_NAMESPACE)
        result_ns = await client.get_namespace_index(MACHINERY_RESULT)
        management = await client.get_node(node_id("st1", ours)).get_child(
            f"{result_ns}:ResultManagement"
        )
        for identifier in cycles:
            node = client.get_node(node_id(f"st1/results/{identifier}", ours))
            value = await node.read_value()
            _handle, by_id, error = await management.call_method(
                f"{result_ns}:GetResultById", identifier, ua.Variant(0, ua.VariantType.Int32)
            )
            assert error == 0 and by_id == value  # from the results store: the same
            found[identifier] = [
                (
                    ref.Value.ResultMetaData.ResultId,
                    ref.Value.ResultMetaData.Classification,
                    int(ref.Value.ResultMetaData.ResultEvaluation),
                    [
                        (c.CounterType, c.CounterValue)
                        for c in ref.Value.ResultMetaData.ResultCounters
                    ],
                )
                for ref in value.ResultContent
            ]
    return found


def test_a_node_opcua_client_receives_each_cycle_as_a_sync_result_of_its_spindles(
    tmp_path: Path,
) -> None:
    modules = needs_node_opcua()
    zenoh_port, opcua_port = free_port(), free_port()
    station = write_station(tmp_path, zenoh_port=zenoh_port)
    certificates = make_opcua_certificates(tmp_path / "pki")
    endpoint = f"opc.tcp://127.0.0.1:{opcua_port}"
    server, log = serve_secure_opcua([station], endpoint, certificates, tmp_path)
    client = start_client(
        modules,
        secure_client_options(
            endpoint,
            certificates,
            "client",
            ["st1"],
            results=CYCLES * (SPINDLES + 1),  # each spindle's result and the cycle's
            connectRetries=240,  # the server listens once its models are loaded
            timeoutMs=CLIENT_TIMEOUT_S * 1000,
        ),
    )
    try:
        heard = wait_subscribed(client, log)
        run_up(station, CYCLES, "--spindles", str(SPINDLES))
        out, err = client.communicate(timeout=CLIENT_TIMEOUT_S)
        assert client.returncode == 0, f"{heard}{out}\n{err}\n{log.read_text()}"
        cycle_ids = [
            line["resultIdField"]
            for line in lines_of(heard + out)
            if line["type"] == "result" and "/cycle/" in line["resultIdField"]
        ]
        references = asyncio.run(_references(endpoint, certificates, cycle_ids))
    finally:
        client.kill()
        server.terminate()
        server.wait(30)
    assert server.returncode == 0, log.read_text()
    (tmp_path / "client.jsonl").write_text(heard + out)  # what it said, for a failure
    events = [line for line in lines_of(heard + out) if line["type"] == "result"]

    with ResultsStore(store_target(station.parent / "recordings", None), create=False) as store:
        stored = [found.result for found in store.find(ResultsQuery(stations=["st1"]))]
    assert len(stored) == CYCLES * SPINDLES
    by_sync: dict[int | None, list[Any]] = defaultdict(list)
    for tightening in stored:
        by_sync[tightening.sync_id].append(tightening)
    assert None not in by_sync  # every tightening a spindle's of a cycle
    assert len(by_sync) == CYCLES
    by_id = {event["resultIdField"]: event for event in events}
    assert len(by_id) == len(events) == CYCLES * (SPINDLES + 1), sorted(by_id)
    for sync_id, spindles in by_sync.items():
        spindles.sort(key=lambda tightening: tightening.spindle)
        assert [t.spindle for t in spindles] == [1, 2]
        for tightening in spindles:  # each spindle's own result names its spindle
            event = by_id[result_id("st1", tightening.run_id)]
            assert event["classificationField"] == SINGLE_RESULT
            assert _counters(event["countersField"]) == {SPINDLE_NUMBER: tightening.spindle}
            assert event["evaluationField"] == EVALUATION[tightening.result]
        assert sync_id is not None
        cycle = by_id[cycle_result_id("st1", sync_id)]
        assert cycle["classificationField"] == SYNC_RESULT
        assert _counters(cycle["countersField"]) == {TOTAL_NUMBER_OF_SPINDLES: SPINDLES}
        every_ok = all(t.result == "OK" for t in spindles)
        assert cycle["evaluationField"] == EVALUATION["OK" if every_ok else "NOK"]
        # a reference per spindle's result (node-opcua decodes the list, not their metadata)
        assert len(cycle["result"]["resultContent"]) == SPINDLES
        assert references[cycle_result_id("st1", sync_id)] == [
            (
                result_id("st1", t.run_id),
                SINGLE_RESULT,
                EVALUATION[t.result],
                [(SPINDLE_NUMBER, t.spindle)],
            )
            for t in spindles
        ]
