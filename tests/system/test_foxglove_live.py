"""A station's runs live in Foxglove, through a real WebSocket on loopback.

``boltwatch up`` runs a real station (router, recorder, acquisition with its
predictor, rig on a CAN bus); beside it a viewer (``serve recorder
--view-only --foxglove-port``, its own scratch folder) serves the Foxglove
WebSocket. A real client (``websockets``, :mod:`tests.support.foxglove_client`)
subscribes before the first run and receives the runs: every sample of a run
one by one (the station sends batches), its decision and its result, each
payload valid against the JSON schema its channel advertised, the same
schemas and the same bytes as the line recorder's MCAP files.
"""

from __future__ import annotations

import json
from collections import defaultdict
from pathlib import Path

import jsonschema
import pytest
from mcap.reader import make_reader

from shared.contract import channels, json_schema
from tests.support.foxglove_client import FoxgloveClient
from tests.support.live_recorder import free_port, wait_until
from tests.support.station_files import serve, write_station
from tests.support.station_up import run_up

pytestmark = pytest.mark.system

STATION = "st1"
RUNS = 3
TOPICS = {
    channel.key(STATION): channel
    for channel in (channels.SAMPLES, channels.DECISION, channels.RESULTS, channels.RUNS)
}


def mcap_payloads(folder: Path) -> dict[str, list[bytes]]:
    """Every payload of the line recorder's files, by topic."""
    found: dict[str, list[bytes]] = defaultdict(list)
    for path in sorted(folder.rglob("*.mcap")):
        with path.open("rb") as handle:
            for _, channel, message in make_reader(handle).iter_messages():
                found[channel.topic].append(message.data)
    return found


def test_a_foxglove_client_receives_the_runs_of_a_real_station_live(tmp_path: Path) -> None:
    zenoh_port, foxglove_port = free_port(), free_port()
    station = write_station(tmp_path, zenoh_port=zenoh_port)
    (tmp_path / "viewer").mkdir()
    viewer_file = write_station(tmp_path / "viewer", zenoh_port=zenoh_port)
    viewer = serve(
        [
            "recorder",
            "--config",
            str(viewer_file),
            "--view-only",
            "--no-rerun",
            "--foxglove-port",
            str(foxglove_port),
        ],
        tmp_path / "viewer.log",
    )
    client = FoxgloveClient(f"ws://127.0.0.1:{foxglove_port}", TOPICS)
    try:
        assert client.subscribed.wait(30), (tmp_path / "viewer.log").read_text()
        assert client.error is None, client.error
        run_up(station, runs=RUNS)
        summaries_key = channels.RUNS.key(STATION)
        wait_until(lambda: len(client.received(summaries_key)) >= RUNS, "the last run summary")
    finally:
        client.close()
        viewer.terminate()
        viewer.wait(30)
    assert client.error is None, client.error
    assert client.subprotocol == "foxglove.sdk.v1"  # the SDK's name of the v1 protocol

    # one channel per (station, channel), the MCAP channel's twin: topic, encoding, schema
    for topic, channel in TOPICS.items():
        advertised = client.channels[topic]
        assert advertised["encoding"] == "json"
        assert advertised["schemaName"] == channel.schema_name
        assert advertised["schemaEncoding"] == "jsonschema"
        assert json.loads(advertised["schema"]) == json_schema(channel.message_type)
    assert channels.SAMPLE_BATCHES.key(STATION) not in client.channels  # served as samples

    served = {topic: client.received(topic) for topic in TOPICS}
    for topic, messages in served.items():  # each payload valid against its schema
        validator = jsonschema.Draft202012Validator(json.loads(client.channels[topic]["schema"]))
        for message in messages:
            validator.validate(json.loads(message.payload))
            assert message.log_time_ns > 0

    summaries = [json.loads(m.payload) for m in served[channels.RUNS.key(STATION)]]
    assert len(summaries) == RUNS
    results = {json.loads(m.payload)["run_id"]: m for m in served[channels.RESULTS.key(STATION)]}
    decisions = [json.loads(m.payload) for m in served[channels.DECISION.key(STATION)]]
    samples_by_run: dict[int, list[int]] = defaultdict(list)
    for message in served[channels.SAMPLES.key(STATION)]:
        sample = json.loads(message.payload)
        samples_by_run[sample["run_id"]].append(sample["sequence"])
    for summary in summaries:
        run = summary["run_id"]
        assert run in results, run
        # every sample of the run, each as a message of its own, in order, none twice
        assert samples_by_run[run] == list(range(summary["samples"])), run
    assert decisions and {d["run_id"] for d in decisions} <= {s["run_id"] for s in summaries}

    # the same bytes as the line recorder's MCAP files hold
    recorded = mcap_payloads(tmp_path / "recordings")
    for topic in (channels.RESULTS.key(STATION), channels.DECISION.key(STATION)):
        assert sorted(m.payload for m in served[topic]) == sorted(recorded[topic]), topic
    samples_key = channels.SAMPLES.key(STATION)
    assert [m.payload for m in served[samples_key]] == recorded[samples_key]
