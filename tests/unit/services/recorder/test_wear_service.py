"""The recorder keeps the wear ledger from RunSummaries on zenoh, answers ``wear``, alerts."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
import zenoh
from mcap.reader import make_reader

from shared.config import LoadedStation, load_station
from shared.contract import RunSummary, ToolState, channels, encode, keys
from tests.support import factories
from tests.support.listener import Listener
from tests.support.live_recorder import (
    RunningRecorder,
    has_subscribers,
    wait_until,
    write_station_file,
)

T0_NS = 1_700_000_000_000_000_000
S_NS = 1_000_000_000
THRESHOLD = 2.0


@pytest.fixture
def station(tmp_path: Path, endpoint: str) -> LoadedStation:
    path = write_station_file(
        tmp_path / "station.toml",
        tmp_path / "recordings",
        listen=[endpoint],
        recorder={"wear_service_threshold": THRESHOLD},
    )
    return load_station(path)


def summary(run_id: int, intensity: float) -> bytes:
    """Run ``run_id`` as put on zenoh: 3 s from T0 + ``run_id`` s, the tool stopped by itself."""
    started = T0_NS + run_id * S_NS
    run = factories.summary(
        run_id,
        events=4,
        stop_reason=None,
        process_intensity=intensity,
        samples=3000,
        started_ns=started,
        ended_ns=started + 3 * S_NS,
    )
    return encode(run)


def test_summaries_count_once_and_a_due_tool_raises_an_alert(
    station: LoadedStation, recorder: RunningRecorder, publisher_session: zenoh.Session
) -> None:
    alerts: list[dict[str, object]] = []
    alert_key = keys.station_key("st1", "wear/alert")
    subscriber = publisher_session.declare_subscriber(
        alert_key, lambda sample: alerts.append(json.loads(sample.payload.to_bytes()))
    )
    tool = publisher_session.declare_publisher(channels.TOOL.key("st1"))
    runs = publisher_session.declare_publisher(channels.RUNS.key("st1"))
    wait_until(lambda: has_subscribers(runs) and has_subscribers(tool), "the recorder")
    tool.put(encode(ToolState("st1", 1, 7, 1, "running", T0_NS)))
    runs.put(summary(1, 1.5))
    runs.put(summary(1, 1.5))  # redelivered
    runs.put(summary(2, 1.0))  # 2.5 >= threshold
    wear = recorder.service.wear
    assert wear is not None  # the line's recorder keeps the ledger (a view does not)
    wait_until(lambda: wear.counted + wear.repeated == 3, "the summaries")
    assert (wear.counted, wear.repeated) == (2, 1)
    wait_until(lambda: len(alerts) == 1, "the wear alert")
    assert alerts[0]["tool_id"] == 7
    assert alerts[0]["intensity_since_service"] == 2.5
    assert alerts[0]["threshold"] == THRESHOLD

    replies = list(publisher_session.get(keys.station_key("st1", keys.WEAR), timeout=10))
    assert len(replies) == 1 and replies[0].ok is not None
    answer = json.loads(replies[0].ok.payload.to_bytes())
    assert answer["station"] == "st1"
    (line,) = answer["tools"]
    assert (line["tool_id"], line["runs"], line["total_intensity"]) == (7, 2, 2.5)
    assert [run["run_id"] for run in line["worst_runs"]] == [1, 2]
    subscriber.undeclare()
    tool.undeclare()
    runs.undeclare()

    recorder.finish()
    (path,) = station.recordings_folder.glob("st1/*/*.mcap")
    with path.open("rb") as handle:
        summary_record = make_reader(handle).get_summary()
    assert summary_record is not None
    schemas = {schema.name for schema in summary_record.schemas.values()}
    assert "boltwatch.WearAlert" in schemas  # the alert is recorded, schema'd


def test_a_ledger_that_cannot_be_written_keeps_the_runs_until_it_can(tmp_path: Path) -> None:
    """A file where the ledger's folder should be: logged, nothing raised, counted later."""
    from services.recorder.wear_watch import WearWatch
    from shared.contract import decode
    from shared.wear import CONTRACT_LIMITS, WearLedger

    blocker = tmp_path / "recordings"
    blocker.write_text("not a folder")
    ledger_file = blocker / "wear.sqlite"
    watch = WearWatch(ledger_file, None, lambda _alert: None, lambda _summary: CONTRACT_LIMITS)
    for run_id in (1, 2):
        assert not watch.on_summary(decode(RunSummary, summary(run_id, 1.0)), T0_NS)
    assert watch.ledger_errors == 2 and watch.last_ledger_error is not None
    blocker.unlink()
    blocker.mkdir()
    assert watch.on_summary(decode(RunSummary, summary(3, 1.0)), T0_NS)  # with the two before
    watch.close()
    assert watch.last_ledger_error is None
    with WearLedger(ledger_file, read_only=True) as ledger:
        assert ledger.tool(7).runs == 3
        assert ledger.tool(7).total_intensity == pytest.approx(3.0)


def test_summaries_beyond_their_bound_are_refused_counted_and_said_in_recorder_stats(
    recorder: RunningRecorder, publisher_session: zenoh.Session
) -> None:
    """The probes on a running recorder: negative intensity (-2e9) and 9e11 (random
    frames on the ToolSensors id), a forged 1e15: none in the ledger, each counted."""
    heard = Listener(publisher_session, "st1", (channels.RECORDER.topic,))
    runs = publisher_session.declare_publisher(channels.RUNS.key("st1"))
    wait_until(lambda: has_subscribers(runs), "the recorder")
    for run_id, intensity in ((1, 1.5), (2, -2e9), (3, 9e11), (4, 1e15), (5, 2.5)):
        runs.put(summary(run_id, intensity))
    wear = recorder.service.wear
    assert wear is not None
    wait_until(lambda: wear.counted + sum(wear.refused.values()) == 5, "the summaries")
    assert (wear.counted, dict(wear.refused)) == (2, {"st1": 3})
    wait_until(lambda: any(s.refused_summaries == 3 for s in heard.of("recorder")), "RecorderStats")
    replies = list(publisher_session.get(keys.station_key("st1", keys.WEAR), timeout=10))
    assert len(replies) == 1 and replies[0].ok is not None
    (line,) = json.loads(replies[0].ok.payload.to_bytes())["tools"]
    assert (line["runs"], line["total_intensity"]) == (2, 4.0)
    heard.close()
    runs.undeclare()
