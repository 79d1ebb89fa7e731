"""The line's OPC UA (IJT) server, used by a client of another implementation (node-opcua)
as a plant's MES or SCADA would.

``boltwatch serve opcua`` serves both stations of a real ``boltwatch up --stations 2
--runs 4`` (router, one acquisition with its predictor and one rig on a CAN bus per
station, recorder with its results store and wear ledger) whose program's torque window
every run ends above: each result is NOK, and each station's third NOK in a row raises
its quality alert; each run's wear is past the service threshold, so each tool's wear
alert is on from its first run. A node-opcua client connects with a client certificate
signed by the CA the server trusts (Basic256Sha256, sign and encrypt) as a user of role
operator, subscribes to the events of the Server object (i=2253) before the first run,
as SCADA systems do, and receives exactly one result-ready event per run of each station
(its ``Result/ResultMetaData/ResultId`` and ``.../ResultEvaluation`` selected as fields
of their own), whose Result equals the results store's tightening: ResultId, part,
program, verdict, creation time, final torque, angle and preload with their windows and
units. With node-opcua's own alarm tools (installAlarmMonitoring) it acknowledges, then
confirms, st1's tool wear condition when it is raised; the line's recorder records both
(``boltwatch/st1/alert/ack``); node-opcua's findActiveConditions (ConditionRefresh) finds
every condition still on. It asks each station's first result by its id
(GetResultById: every sample the recording holds, value for value) and the latest
(GetLatestResult, also through MachineryBuildingBlocks/ResultManagement: the same
object), reads each tool's counters from the wear ledger, and walks the whole address
space (every node browsed and read, every type definition resolved: none fails). A
client without a certificate (security None), a client whose certificate the CA did not
sign and one with a wrong password are refused, each of the two the server sees in one
line of its log.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from datetime import datetime
from pathlib import Path
from typing import Any

import pytest

from services.opcua.controller_values import BOLTWATCH
from services.opcua.joining_systems import result_browse_name
from services.opcua.result_trace import recorded_samples
from services.opcua.result_values import DEGREE, NEWTON, NEWTON_METRE, result_id
from services.opcua.tool_assets import ONE, tool_browse_name
from shared.config import derive_stations
from shared.contract import channels
from shared.recordings import software_version
from shared.results import ResultsQuery, ResultsStore, StoredResult, store_target
from shared.wear import WearLedger, ledger_path
from tests.support.address_space_picture import screenshot, tree_page
from tests.support.chromium import CHROMIUM
from tests.support.live_recorder import free_port
from tests.support.opcua_certificates import (
    OpcuaCertificates,
    client_uri,
    make_opcua_certificates,
)
from tests.support.opcua_client import lines_of, run_client, start_client
from tests.support.opcua_line import (
    USER,
    needs_node_opcua,
    secure_client_options,
    serve_secure_opcua,
    wait_subscribed,
)
from tests.support.paths import REPO
from tests.support.station_files import write_station
from tests.support.station_up import read_recordings, run_up

pytestmark = pytest.mark.system

STATIONS = ["st1", "st2"]
RUNS = 4  # per station: the quality alert at the third NOK in a row (quality.nok_run)
CLIENT_TIMEOUT_S = 120
THRESHOLD = 500.0  # the station's recorder.wear_service_threshold: below one run's
#: program 1's torque window: every run ends above it (at about 200 N·m), NOK
NOK_TORQUE_MIN_NM, NOK_TORQUE_MAX_NM = 50.0, 100.0
WEAR_CONDITION = "Wear of tool 7"  # st1's tool
QUALITY_CONDITION = "Quality of program 1: nok_run"
COMMENT = "socket changed at the next stop"
#: what the browser's view of the joining system shows expanded
EXPANDED = [
    "Identification",
    "AssetManagement",
    "AssetManagement/Assets",
    "AssetManagement/Assets/Controllers",
    "AssetManagement/Assets/Controllers/*",
    "AssetManagement/Assets/Controllers/*/Identification",
    "AssetManagement/Assets/Tools",
    "AssetManagement/Assets/Tools/*",
    "AssetManagement/Assets/Tools/*/LifetimeCounters",
    "AssetManagement/Assets/Tools/*/Maintenance",
    "ResultManagement",
    "ResultManagement/Results",
]
DOCS_IMAGE = REPO / "docs" / "images" / "opcua-address-space.png"


def _options(
    endpoint: str, certificates: OpcuaCertificates, name: str, **more: Any
) -> dict[str, Any]:
    return secure_client_options(endpoint, certificates, name, STATIONS, **more)


def _lines(lines: list[dict[str, Any]], kind: str, station: str) -> list[dict[str, Any]]:
    """The client's lines of ``kind`` about ``station``."""
    return [line for line in lines if line["type"] == kind and line.get("station") == station]


def _value(values: list[dict[str, Any]], name: str) -> dict[str, Any]:
    found = [value for value in values if value["name"] == name]
    assert len(found) == 1, f"{name} in {values}"
    return found[0]


def test_a_node_opcua_client_handles_the_results_and_alerts_of_a_real_line(
    tmp_path: Path,
) -> None:
    modules = needs_node_opcua()
    zenoh_port, opcua_port = free_port(), free_port()
    station = write_station(
        tmp_path,
        zenoh_port=zenoh_port,
        replacements={
            "[recorder]\n": f"[recorder]\nwear_service_threshold = {THRESHOLD}\n",
            "torque_min_nm = 180.0\ntorque_max_nm = 240.0": (
                f"torque_min_nm = {NOK_TORQUE_MIN_NM}\ntorque_max_nm = {NOK_TORQUE_MAX_NM}"
            ),
        },
    )
    # the files `up --stations 2` derives (the same, written before it starts)
    stations = derive_stations(station, len(STATIONS), tmp_path / "stations")
    certificates = make_opcua_certificates(tmp_path / "pki", untrusted=("stranger",))
    endpoint = f"opc.tcp://127.0.0.1:{opcua_port}"
    server, log = serve_secure_opcua(stations, endpoint, certificates, tmp_path)
    client = start_client(
        modules,
        _options(
            endpoint,
            certificates,
            "client",
            results=RUNS * len(STATIONS),
            askById=True,
            askLatest=True,
            toolRuns=RUNS,
            browseTree={"expand": EXPANDED},
            acknowledge={"conditionName": WEAR_CONDITION, "comment": COMMENT},
            crawl=True,
            # about 2 min of tries: the server listens once its models are loaded (10 s and
            # more on a loaded machine; the client's default 40 tries, 20 s, ran out)
            connectRetries=240,
            timeoutMs=CLIENT_TIMEOUT_S * 1000,
        ),
    )
    try:
        heard = wait_subscribed(client, log)
        run_up(station, RUNS, "--stations", str(len(STATIONS)))
        out, err = client.communicate(timeout=CLIENT_TIMEOUT_S)
        assert client.returncode == 0, f"{heard}{out}\n{err}\n{log.read_text()}"
        lines = lines_of(heard + out)
        (tmp_path / "client.jsonl").write_text(heard + out)  # what it said, for a failure

        refused = {
            "security None": run_client(
                modules,
                _options(endpoint, certificates, "client", security="None", connectRetries=1),
                timeout_s=60,
            ),
            "untrusted certificate": run_client(
                modules,
                _options(endpoint, certificates, "stranger", connectRetries=1),
                timeout_s=60,
            ),
            "wrong password": run_client(
                modules,
                _options(endpoint, certificates, "client", password="wrong", connectRetries=1),
                timeout_s=60,
            ),
        }
    finally:
        client.kill()
        server.terminate()
        server.wait(30)
    assert server.returncode == 0, log.read_text()

    assert lines[0] == {"type": "connected", "securityMode": "SignAndEncrypt"}
    assert [line["station"] for line in lines if line["type"] == "system"] == STATIONS
    recordings = station.parent / "recordings"
    target = store_target(recordings, None)
    with ResultsStore(target, create=False) as store:
        found = {st: store.find(ResultsQuery(stations=[st], oldest_first=True)) for st in STATIONS}
    for st in STATIONS:
        stored = [s.result for s in found[st]]
        assert len(stored) == RUNS and {r.result for r in stored} == {"NOK"}
        events = [line for line in lines if line["type"] == "result" and line["station"] == st]
        # on the Server object: exactly one event per run (node-opcua may hand a client
        # notifications out of their order: it decodes a structure of the models before it
        # hands it over, and one without after)
        by_id = {result_id(st, r.run_id): r for r in stored}
        assert sorted(e["resultIdField"] for e in events) == sorted(by_id)
        _check_results(events, by_id)
        _check_trace(lines, st, found[st][0])
        [latest] = _lines(lines, "latest", st)
        assert (latest["resultId"], latest["error"]) == (result_id(st, stored[-1].run_id), 0)
        assert latest["tracePoints"] > 100  # the last run's samples at 1 kHz
        [blocks] = _lines(lines, "latest_blocks", st)
        assert blocks["objectId"] == blocks["systemObjectId"]  # one ResultManagement
        assert (blocks["status"], blocks["resultId"], blocks["error"]) == (
            "Good", latest["resultId"], 0
        )  # fmt: skip
        [folder] = _lines(lines, "results_folder", st)
        assert folder["names"] == [result_browse_name(r.run_id) for r in stored]
    _check_tools(lines, recordings)
    _check_conditions(lines, recordings)
    _check_crawl(lines)
    _check_tree(lines, [s.result for s in found["st1"]], endpoint, tmp_path)
    _check_refusals(refused, log.read_text())


def _check_results(events: list[dict[str, Any]], stored: dict[str, Any]) -> None:
    """Each event's Result equals the results store's tightening (a NOK one)."""
    for event in events:
        expected = stored[event["resultIdField"]]
        result = event["result"]
        meta = result["resultMetaData"]
        assert (
            meta["resultId"]
            == event["resultIdField"]
            == result_id(expected.station, expected.run_id)
        )
        assert meta["partId"] == expected.part_id
        assert meta["internalRecipeId"] == str(expected.program_id)
        assert meta["resultState"] == 1
        assert meta["resultEvaluation"] == event["evaluationField"] == 2, json.dumps(meta)  # NotOK
        # JoiningResultMetaDataType's own optional fields (Classification, Name, ...) are not
        # compared: node-opcua 2.186 numbers a subtype's optional-field bits after every field
        # of its supertype, mandatory ones too (one bit off from OPC 10000-6, 5.2.7, which
        # asyncua follows); tests/unit/services/opcua/test_result_encoding.py checks them
        created_ns = int(datetime.fromisoformat(meta["creationTime"]).timestamp() * 1e9)
        assert abs(created_ns - expected.time_ns) < 1_000_000  # a UtcTime holds 100 ns steps
        [content] = result["resultContent"]
        values = content["value"]["overallResultValues"]
        for name, figure, unit in (
            ("Torque", expected.final_torque_nm, NEWTON_METRE),
            ("Angle", expected.final_angle_deg, DEGREE),
            ("Preload", expected.final_force_n, NEWTON),
        ):
            value = _value(values, name)
            assert value["measuredValue"] == figure.value
            assert value["lowLimit"] == figure.min
            assert value["highLimit"] == figure.max
            assert value["engineeringUnits"]["unitId"] == unit.unit_id
        assert _value(values, "Torque")["resultEvaluation"] == 2  # above its window: the NOK
        assert _value(values, "StickSlipEvents")["measuredValue"] == expected.events


def _check_conditions(lines: list[dict[str, Any]], recordings: Path) -> None:
    """The wear and quality alerts as conditions on the Server object; st1's tool wear
    acknowledged and confirmed by the SCADA's user (node-opcua's alarm tools), recorded by
    the line's recorder; ConditionRefresh returns every condition still on."""
    conditions = [line for line in lines if line["type"] == "event"]
    assert {c["eventType"].rsplit(";", 1)[1] for c in conditions} == {"i=1020"}
    names = {(c["station"], c["conditionName"]) for c in conditions}
    assert {("st1", WEAR_CONDITION), ("st2", "Wear of tool 8")} <= names
    assert {("st1", QUALITY_CONDITION), ("st2", QUALITY_CONDITION)} <= names
    wear = [c for c in conditions if c["conditionName"] == WEAR_CONDITION]
    # raised, acknowledged (and confirmed), raised again at each run (node-opcua may hand
    # them over out of their order)
    assert {(c["retain"], c["acked"]) for c in wear} == {(True, False), (True, True)}
    assert all(c["message"].startswith("tool 7: stick-slip intensity since") for c in wear)
    [acknowledged] = [line for line in lines if line["type"] == "acknowledged"]
    [confirmed] = [line for line in lines if line["type"] == "confirmed"]
    assert (acknowledged["station"], acknowledged["status"], confirmed["status"]) == (
        "st1", "Good", "Good"
    )  # fmt: skip
    [retained] = [line for line in lines if line["type"] == "retained"]
    refreshed = {(c["station"], c["conditionName"]): c for c in retained["conditions"]}
    assert set(refreshed) == names  # every alert is still on: each one retained
    st1_wear = refreshed[("st1", WEAR_CONDITION)]
    assert (st1_wear["retain"], st1_wear["acked"], st1_wear["confirmed"]) == (True, True, True)
    assert refreshed[("st2", "Wear of tool 8")]["acked"] is False
    # the acknowledgement and the confirmation, as the line's recorder recorded them
    records = read_recordings(recordings)[channels.ALERT_ACK.key("st1")]
    assert [(r["action"], r["condition"], r["user"]) for r in records] == [
        ("acknowledged", "wear/7", USER),
        ("confirmed", "wear/7", USER),
    ]
    assert records[0]["client"] == client_uri("client") and records[0]["comment"] == COMMENT
    assert records[0]["active"] is True


def _check_crawl(lines: list[dict[str, Any]]) -> None:
    """node-opcua walked the whole address space: every node browsed and read, every
    variable's value read, every type definition a reference names resolved."""
    [crawl] = [line for line in lines if line["type"] == "crawl"]
    print(  # what the crawl found, in the test's output
        "crawl:",
        json.dumps({k: v for k, v in crawl.items() if k != "failures"}),
        f"failures {len(crawl['failures'])}",
    )
    assert crawl["failures"] == [], crawl["failures"][:20]
    assert crawl["nodes"] > 8000 and crawl["variables"] > 4000 and crawl["typeDefinitions"] > 100
    ours = crawl["byNamespace"]["urn:boltwatch:opcua"]
    assert ours["Object"] > 0 and ours["Variable"] > 0 and ours["Method"] > 0


def _check_refusals(refused: dict[str, list[dict[str, Any]]], log: str) -> None:
    """Each refused client is refused, and leaves one line in the server's log, without a
    traceback (the client without security none: node-opcua finds no endpoint it can use and
    opens no session; an anonymous session is refused the same way, by node-opcua itself,
    and in test_session_users.py by the server)."""
    for name, said in refused.items():
        assert [line["type"] for line in said] == ["refused"], (name, said)
    assert "BadUserAccessDenied" in refused["wrong password"][0]["reason"]
    assert "Traceback" not in log
    lines = [line for line in log.splitlines() if "refused" in line]
    assert len(lines) == 2, lines
    assert "stranger" in lines[0] and "BadCertificateUntrusted" in lines[0]
    assert f"user {USER!r} refused" in lines[1]


def _check_trace(lines: list[dict[str, Any]], station: str, first: StoredResult) -> None:
    """The station's first result asked by id holds every sample of its recording."""
    [asked] = [line for line in lines if line["type"] == "by_id" and line["station"] == station]
    identifier = result_id(station, first.result.run_id)
    assert (asked["resultId"], asked["error"]) == (identifier, 0)
    assert asked["result"]["resultMetaData"]["resultId"] == identifier
    assert first.recording is not None
    samples = recorded_samples(Path(first.recording), station, first.result.run_id)
    assert len(samples) > 100  # a whole run at 1 kHz
    [content] = asked["result"]["resultContent"]
    [step] = content["value"]["trace"]["stepTraces"]
    assert step["numberOfTracePoints"] == len(samples)
    assert step["samplingInterval"] == 1.0  # ms: the station's 1 kHz
    channels = {item["name"]: item["values"] for item in step["stepTraceContent"]}
    assert channels["Torque"] == [sample["torque_nm"] for sample in samples]
    assert channels["Angle"] == [sample["angle_deg"] for sample in samples]
    assert channels["Preload"] == [sample["force_n"] for sample in samples]  # None: NaN


def _check_tree(
    lines: list[dict[str, Any]], stored: list[Any], endpoint: str, tmp_path: Path
) -> None:
    """The joining system as a generic browser shows it: its results, its tool with the
    counters, its methods; photographed where chromium is (``BOLTWATCH_DOCS_IMAGES=1``: the
    picture of docs/how-to/opcua.md)."""
    [tree] = [line for line in lines if line["type"] == "tree" and line["station"] == "st1"]
    nodes = {node["path"]: node for node in tree["nodes"]}
    assert nodes[""]["type"] == "JoiningSystemType"
    assert nodes["Identification/SystemId"]["value"] == "st1"
    assert nodes["Identification/JoiningTechnology"]["value"] == "Tightening"
    results = [path for path in nodes if path.startswith("ResultManagement/Results/")]
    assert results == [f"ResultManagement/Results/{result_browse_name(r.run_id)}" for r in stored]
    assert {nodes[path]["type"] for path in results} == {"JoiningSystemResultType"}
    assert nodes["ResultManagement/GetResultById"]["nodeClass"] == "Method"
    tool = f"AssetManagement/Assets/Tools/{tool_browse_name(stored[0].tool_id)}"
    counter = nodes[f"{tool}/LifetimeCounters/StickSlipIntensitySinceService"]
    assert (counter["type"], counter["dataType"]) == ("LifetimeVariableType", "Double")
    assert counter["value"] > 0
    # the station's controller: boltwatch's acquisition (a CAN station)
    controller = "AssetManagement/Assets/Controllers/Controller"
    assert nodes[f"{controller}/Identification/Manufacturer"]["value"] == BOLTWATCH
    assert nodes[f"{controller}/Identification/SoftwareRevision"]["value"] == software_version()
    assert nodes[f"{controller}/Parameters"]["children"] == 1
    if not CHROMIUM.exists():
        return  # the line page's test says why where chromium is missing
    shot = tmp_path / "opcua-address-space.png"
    screenshot(tree_page(tree["nodes"], f"{endpoint} — Objects/Machines/st1"), shot)
    assert shot.stat().st_size > 10_000
    if os.environ.get("BOLTWATCH_DOCS_IMAGES") == "1":
        shutil.copyfile(shot, DOCS_IMAGE)


def _check_tools(lines: list[dict[str, Any]], recordings: Path) -> None:
    """Each station's tool in AssetManagement/Assets/Tools with the wear ledger's counters."""
    for st in STATIONS:
        with WearLedger(ledger_path(recordings), read_only=True) as ledger:
            [wear] = ledger.tools(station=st)
        [tool] = [line for line in lines if line["type"] == "tool" and line["station"] == st]
        assert tool["name"] == tool_browse_name(wear.tool_id)
        assert (
            (tool["tightenings"], tool["sinceService"])
            == (RUNS, RUNS)
            == (wear.runs, wear.runs_since_service)
        )
        assert tool["intensitySinceService"] == wear.intensity_since_service > 0
        assert (tool["limitValue"], tool["unitId"]) == (THRESHOLD, ONE.unit_id)
        # warned at 0.8 and 0.95 of the threshold; past it (one run is more): due, no date
        assert tool["warningValues"] == [0.8 * THRESHOLD, 0.95 * THRESHOLD]
        assert (tool["serviceDue"], tool["tighteningsToService"]) == (None, 0)
        assert tool["serialNumber"] == ""  # no controller named the simulated tool


def test_serve_opcua_says_what_security_it_needs(tmp_path: Path) -> None:
    station = write_station(tmp_path)
    done = subprocess.run(
        [sys.executable, "-m", "services.cli", "serve", "opcua", "--config", str(station)],
        capture_output=True,
        text=True,
        timeout=60,
        check=False,
    )
    assert done.returncode != 0
    assert "--certificate, --private-key, --trusted-clients, --users" in done.stderr, done.stderr
    assert "--anonymous-read-only" in done.stderr
