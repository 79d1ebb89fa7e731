"""The line's OPC UA (IJT) server, read by a client of another implementation (node-opcua).

``boltwatch serve opcua`` serves the station of a real ``boltwatch up --runs 5``
(router, acquisition with its predictor, rig on a CAN bus, recorder with its
results store). A node-opcua client connects with a client certificate signed
by the CA the server trusts (Basic256Sha256, sign and encrypt), browses to the
station's joining system (Objects/Machines/st1), subscribes to its events before
the first run, and receives one result-ready event per run whose Result equals
the results store's tightening: its ResultId, part, program, verdict, creation
time and final torque, angle and preload with their windows and units. It asks
the first result by its id (ResultManagement's GetResultById) and finds in its
trace every sample the recording holds of the run, value for value, and asks
the latest result (GetLatestResult: the last run's, with its trace); it reads
the station's tool with its counters from the wear ledger (tightenings, since
service, stick-slip intensity since service against the threshold), and
receives the recorder's wear alerts as the joining system's events. The client
logs in with a user name and password of the server's users file. A client
without a certificate (security None), a client whose certificate the CA did
not sign and a client with a wrong password are refused.
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
from services.opcua.nodeset_files import missing_files, nodeset_folder
from services.opcua.password_hashes import hash_password
from services.opcua.result_trace import recorded_samples
from services.opcua.result_values import DEGREE, NEWTON, NEWTON_METRE, result_id
from services.opcua.tool_assets import ONE, tool_browse_name
from services.opcua.users_file import OpcuaUser, write_users
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
from tests.support.opcua_client import lines_of, node_opcua_client, run_client, start_client
from tests.support.paths import REPO
from tests.support.station_files import serve, write_station
from tests.support.station_up import run_up

pytestmark = pytest.mark.system

STATION = "st1"
RUNS = 5
CLIENT_TIMEOUT_S = 120
THRESHOLD = 500.0  # the station's recorder.wear_service_threshold: below one run's
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
USER, PASSWORD = "line-mes", "a password of the line's MES"


def _needs() -> Path:
    if missing_files(nodeset_folder()):
        pytest.skip("the OPC UA models are not fetched (`make opcua-nodesets` needs npm)")
    modules, reason = node_opcua_client()
    if modules is None:
        pytest.skip(reason)
    return modules


def _options(
    endpoint: str, certificates: OpcuaCertificates, name: str, **more: Any
) -> dict[str, Any]:
    certificate, key = certificates.clients[name]
    return {
        "endpoint": endpoint,
        "certificate": str(certificate),
        "privateKey": str(key),
        "applicationUri": client_uri(name),
        "security": "SignAndEncrypt",
        "stations": [STATION],
        "userName": USER,
        "password": PASSWORD,
        **more,
    }


def _value(values: list[dict[str, Any]], name: str) -> dict[str, Any]:
    found = [value for value in values if value["name"] == name]
    assert len(found) == 1, f"{name} in {values}"
    return found[0]


def test_a_node_opcua_client_receives_the_results_of_a_real_line(tmp_path: Path) -> None:
    modules = _needs()
    zenoh_port, opcua_port = free_port(), free_port()
    station = write_station(
        tmp_path,
        zenoh_port=zenoh_port,
        replacements={"[recorder]\n": f"[recorder]\nwear_service_threshold = {THRESHOLD}\n"},
    )
    certificates = make_opcua_certificates(tmp_path / "pki", untrusted=("stranger",))
    endpoint = f"opc.tcp://127.0.0.1:{opcua_port}"
    users = tmp_path / "opcua-users.toml"
    write_users(users, {USER: OpcuaUser(USER, hash_password(PASSWORD))})
    log = tmp_path / "opcua.log"
    server = serve(
        [
            "opcua",
            "--config",
            str(station),
            "--listen",
            endpoint,
            "--certificate",
            str(certificates.server_certificate),
            "--private-key",
            str(certificates.server_key),
            "--trusted-clients",
            str(certificates.trusted_clients),
            "--users",
            str(users),
        ],
        log,
    )
    client = start_client(
        modules,
        _options(
            endpoint,
            certificates,
            "client",
            results=RUNS,
            askById=True,
            askLatest=True,
            toolRuns=RUNS,
            browseTree={"expand": EXPANDED},
            # about 2 min of tries: the server listens once its models are loaded (10 s and
            # more on a loaded machine; the client's default 40 tries, 20 s, ran out)
            connectRetries=240,
            timeoutMs=CLIENT_TIMEOUT_S * 1000,
        ),
    )
    try:
        assert client.stdout is not None
        heard = ""
        while "subscribed" not in heard:
            line = client.stdout.readline()
            assert line, f"the client ended: {heard}\n{log.read_text()}"
            heard += line
        run_up(station, runs=RUNS)
        out, err = client.communicate(timeout=CLIENT_TIMEOUT_S)
        assert client.returncode == 0, f"{heard}{out}\n{err}\n{log.read_text()}"
        lines = lines_of(heard + out)

        refused = run_client(
            modules,
            _options(endpoint, certificates, "client", security="None", connectRetries=1),
            timeout_s=60,
        )
        stranger = run_client(
            modules,
            _options(endpoint, certificates, "stranger", connectRetries=1),
            timeout_s=60,
        )
        wrong_password = run_client(
            modules,
            _options(endpoint, certificates, "client", password="wrong", connectRetries=1),
            timeout_s=60,
        )
    finally:
        client.kill()
        server.terminate()
        server.wait(30)
    assert server.returncode == 0, log.read_text()

    assert lines[0] == {"type": "connected", "securityMode": "SignAndEncrypt"}
    assert [line["station"] for line in lines if line["type"] == "system"] == [STATION]
    events = [line for line in lines if line["type"] == "result"]
    assert len(events) == RUNS, lines

    target = store_target(station.parent / "recordings", None)
    with ResultsStore(target, create=False) as store:
        found = store.find(ResultsQuery(stations=[STATION], oldest_first=True))
    stored = [s.result for s in found]
    assert len(stored) == RUNS
    for event, expected in zip(events, stored, strict=True):
        result = event["result"]
        meta = result["resultMetaData"]
        assert meta["resultId"] == result_id(STATION, expected.run_id)
        assert meta["partId"] == expected.part_id
        assert meta["internalRecipeId"] == str(expected.program_id)
        assert meta["resultState"] == 1
        assert meta["resultEvaluation"] == (1 if expected.result == "OK" else 2), json.dumps(meta)
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
        assert _value(values, "StickSlipEvents")["measuredValue"] == expected.events
    [folder] = [line for line in lines if line["type"] == "results_folder"]
    assert folder["names"] == [result_browse_name(r.run_id) for r in stored]
    _check_trace(lines, found[0])
    [latest] = [line for line in lines if line["type"] == "latest"]
    assert (latest["resultId"], latest["error"]) == (result_id(STATION, stored[-1].run_id), 0)
    assert latest["tracePoints"] > 100  # the last run's samples at 1 kHz
    _check_tools(lines, station.parent / "recordings")
    _check_tree(lines, stored, endpoint, tmp_path)

    assert [line["type"] for line in refused] == ["refused"], refused
    assert [line["type"] for line in stranger] == ["refused"], stranger
    assert [line["type"] for line in wrong_password] == ["refused"], wrong_password
    assert "BadUserAccessDenied" in wrong_password[0]["reason"], wrong_password


def _check_trace(lines: list[dict[str, Any]], first: StoredResult) -> None:
    """The first result asked by id holds every sample of its recording."""
    [asked] = [line for line in lines if line["type"] == "by_id"]
    identifier = result_id(STATION, first.result.run_id)
    assert (asked["resultId"], asked["error"]) == (identifier, 0)
    assert asked["result"]["resultMetaData"]["resultId"] == identifier
    assert first.recording is not None
    samples = recorded_samples(Path(first.recording), STATION, first.result.run_id)
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
    [tree] = [line for line in lines if line["type"] == "tree"]
    nodes = {node["path"]: node for node in tree["nodes"]}
    assert nodes[""]["type"] == "JoiningSystemType"
    assert nodes["Identification/SystemId"]["value"] == STATION
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
    screenshot(tree_page(tree["nodes"], f"{endpoint} — Objects/Machines/{STATION}"), shot)
    assert shot.stat().st_size > 10_000
    if os.environ.get("BOLTWATCH_DOCS_IMAGES") == "1":
        shutil.copyfile(shot, DOCS_IMAGE)


def _check_tools(lines: list[dict[str, Any]], recordings: Path) -> None:
    """The station's tool in AssetManagement/Assets/Tools with the wear ledger's counters."""
    with WearLedger(ledger_path(recordings), read_only=True) as ledger:
        [wear] = ledger.tools(station=STATION)
    [tool] = [line for line in lines if line["type"] == "tool"]
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
    # the recorder's wear alerts (the threshold is below one run's intensity) as the joining
    # system's JoiningSystemEventType events
    alerts = [line for line in lines if line["type"] == "event"]
    assert alerts, lines
    for alert in alerts:
        assert alert["eventType"].endswith(";i=1006")
        assert alert["message"].startswith(f"tool {wear.tool_id}: stick-slip intensity since")


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
