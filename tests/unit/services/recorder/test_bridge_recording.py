"""What a controller bridge publishes, recorded: its tool data, alarms and
counters into MCAP with their schemas, the tool data into the wear ledger beside the runs
(an older ledger migrated without losing it), shown by ``boltwatch wear``."""

from __future__ import annotations

import json
import sqlite3
from dataclasses import replace
from pathlib import Path

import pytest
import zenoh
from mcap.reader import make_reader

from services.cli.main import main
from shared.config import LoadedStation
from shared.contract import (
    ControllerAlarm,
    RunSummary,
    ToolData,
    ToolState,
    channels,
    decode,
    json_schema,
    keys,
)
from shared.wear import (
    APPLICATION_ID,
    LEDGER_VERSION,
    BrokenLedgerError,
    WearLedger,
    ledger_path,
    merge,
    parse_reply,
)
from shared.wear import COLUMNS as LEDGER_COLUMNS
from shared.wear import CONTRACT_LIMITS as LIMITS
from tests.support import factories
from tests.support.fuzz.payloads import template
from tests.support.live_recorder import RunningRecorder, publish, wait_until

T0_NS = 1_700_000_000_000_000_000
S_NS = 1_000_000_000
DAY_NS = 86_400 * S_NS


def tool_data(time_ns: int = T0_NS, **changes: object) -> ToolData:
    made: ToolData = template("tool_data", "st1", time_ns)
    made = replace(made, tool_id=7, last_calibration_ns=T0_NS - 30 * DAY_NS)
    return replace(made, last_service_ns=T0_NS - 90 * DAY_NS, **changes)  # type: ignore[arg-type]


def summary(run_id: int, intensity: float, station: str = "st1") -> RunSummary:
    """A bridge's run to 1.4 Nm (no force sensor), ended ``run_id`` seconds after T0."""
    ended = T0_NS + run_id * S_NS
    return factories.summary(
        run_id,
        station=station,
        target_force_n=None,
        target_torque_nm=1.4,
        reached_force_n=None,
        reached_torque_nm=1.42,
        error_pct=1.4,
        events=4,
        stop_reason=None,
        process_intensity=intensity,
        samples=500,
        started_ns=ended - S_NS // 2,
        ended_ns=ended,
    )


def test_a_bridges_messages_are_recorded_with_their_schemas_and_its_tool_in_the_ledger(
    station: LoadedStation,
    recorder: RunningRecorder,
    publisher_session: zenoh.Session,
    capsys: pytest.CaptureFixture[str],
) -> None:
    alarm = ControllerAlarm("st1", T0_NS, T0_NS + 5, "E404", "raised", True, False, True, "hot")
    stats = template("openprotocol", "st1", T0_NS + S_NS, run_id=1)
    sent = [
        (channels.TOOL.topic, ToolState("st1", 1, 7, 1, "running", T0_NS)),
        (channels.TOOL_DATA.topic, tool_data()),
        (channels.ALARMS.topic, alarm),
        (channels.OPENPROTOCOL.topic, stats),
        (channels.RUNS.topic, summary(1, 0.75)),
        # a newer word of the controller (a service since), then an older one arriving late
        (channels.TOOL_DATA.topic, tool_data(T0_NS + 2 * S_NS, tightenings_since_service=0)),
        (channels.TOOL_DATA.topic, tool_data(T0_NS + S_NS, tool_serial="OLD")),
    ]
    publish(publisher_session, sent)
    wear = recorder.service.wear
    assert wear is not None
    wait_until(lambda: wear.counted == 1 and wear.tool_data_kept == 2, "the run and tool data")

    replies = list(publisher_session.get(keys.station_key("st1", keys.WEAR), timeout=10))
    (reply,) = [parse_reply(r.ok.payload.to_bytes()) for r in replies if r.ok is not None]
    (line,) = reply.tools
    assert (line.tool_id, line.runs, line.total_intensity) == (7, 1, 0.75)
    assert line.controller is not None
    assert (line.controller.tool_serial, line.controller.tightenings_since_service) == (
        "B1234567",
        0,
    )  # the newest word kept, the late older one not
    assert line.controller.last_calibration_ns == T0_NS - 30 * DAY_NS
    recorder.finish()

    (path,) = station.recordings_folder.glob("st1/*/*.mcap")
    with path.open("rb") as handle:
        reader = make_reader(handle)
        by_topic: dict[str, list[bytes]] = {}
        for schema, channel, message in reader.iter_messages():
            assert schema is not None
            by_topic.setdefault(channel.topic, []).append(message.data)
            expected = channels.by_topic(keys.split_key(channel.topic)[1])
            assert expected is not None and schema.name == expected.schema_name
            assert json.loads(schema.data) == json_schema(expected.message_type)
    assert [decode(ToolData, d) for d in by_topic["boltwatch/st1/tool_data"]] == [
        message for topic, message in sent if topic == channels.TOOL_DATA.topic
    ]
    assert [decode(ControllerAlarm, d) for d in by_topic["boltwatch/st1/alarms"]] == [alarm]
    assert [decode(type(stats), d) for d in by_topic["boltwatch/st1/openprotocol"]] == [stats]

    assert main(["wear", "--recordings", str(station.recordings_folder)]) == 0
    table = capsys.readouterr().out.splitlines()
    assert table[0].split()[:3] == ["tool", "serial", "runs"]
    assert "calibrated" in table[0] and "tool service" in table[0]
    assert table[1].split()[:3] == ["7", "B1234567", "1"]
    assert "2023-10-15" in table[1] and "2023-08-16" in table[1]  # calibrated, serviced


VERSION_1 = """
CREATE TABLE runs (
    station TEXT NOT NULL, run_id INTEGER NOT NULL, tool_id INTEGER NOT NULL,
    program_id INTEGER NOT NULL, tool_state TEXT NOT NULL, stop_reason TEXT,
    events INTEGER NOT NULL, process_intensity REAL NOT NULL, started_ns INTEGER NOT NULL,
    ended_ns INTEGER NOT NULL, recorded_ns INTEGER NOT NULL, PRIMARY KEY (station, run_id)
);
CREATE TABLE services (
    id INTEGER PRIMARY KEY AUTOINCREMENT, tool_id INTEGER NOT NULL,
    serviced_ns INTEGER NOT NULL, note TEXT NOT NULL
);
"""


def ledger_of_version_1(path: Path) -> None:
    """A ledger as boltwatch made it before tool data: two runs and a service of tool 7."""
    db = sqlite3.connect(path)
    db.execute(f"PRAGMA application_id = {APPLICATION_ID}")
    db.execute("PRAGMA journal_mode=WAL")
    db.executescript(VERSION_1)
    for run_id, intensity in ((1, 1.0), (2, 2.0)):
        s = summary(run_id, intensity)
        db.execute(
            "INSERT INTO runs VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?)",
            (s.station, s.run_id, s.tool_id, s.program_id, s.tool_state, s.stop_reason,
             s.events, s.process_intensity, s.started_ns, s.ended_ns, T0_NS),
        )  # fmt: skip
    db.execute(
        "INSERT INTO services (tool_id, serviced_ns, note) VALUES (7, ?, 'new socket')", (T0_NS,)
    )
    db.commit()
    db.close()


def test_a_ledger_made_before_tool_data_is_read_as_it_is_and_migrated_by_its_writer(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = ledger_path(tmp_path)
    ledger_of_version_1(path)
    with WearLedger(path, read_only=True) as reader:  # `boltwatch wear` on an old ledger
        seven = reader.tool(7)
    assert (seven.runs, seven.total_intensity, seven.controller) == (2, 3.0, None)
    assert main(["wear", "--recordings", str(tmp_path)]) == 0
    assert capsys.readouterr().out.splitlines()[1].split()[:3] == ["7", "-", "2"]

    with WearLedger(path) as ledger:  # a recorder opens it: the table is added, nothing lost
        assert ledger.add_tool_data(tool_data(), T0_NS)
        assert not ledger.add_tool_data(tool_data(T0_NS - S_NS, tool_serial="OLD"), T0_NS)
        assert ledger.add_run(summary(3, 4.0), T0_NS, LIMITS)
        seven = ledger.tool(7)
    assert (seven.runs, seven.total_intensity, seven.last_service_note) == (3, 7.0, "new socket")
    assert seven.controller is not None and seven.controller.tool_serial == "B1234567"
    db = sqlite3.connect(path)
    try:
        assert db.execute("PRAGMA user_version").fetchone() == (LEDGER_VERSION,)
        columns = tuple(row[1] for row in db.execute("PRAGMA table_info(tool_data)"))
        assert columns == LEDGER_COLUMNS["tool_data"]
    finally:
        db.close()


def test_a_ledger_of_a_newer_version_or_a_wrong_tool_data_table_is_not_written(
    tmp_path: Path,
) -> None:
    path = ledger_path(tmp_path)
    ledger_of_version_1(path)
    db = sqlite3.connect(path)
    db.execute(f"PRAGMA user_version = {LEDGER_VERSION + 1}")
    db.commit()
    db.close()
    with pytest.raises(BrokenLedgerError, match=f"a ledger of version {LEDGER_VERSION + 1}, newer"):
        WearLedger(path)
    other = ledger_path(tmp_path / "other")
    other.parent.mkdir()
    ledger_of_version_1(other)
    db = sqlite3.connect(other)
    db.execute("CREATE TABLE tool_data (station TEXT, serial TEXT)")
    db.commit()
    db.close()
    with pytest.raises(BrokenLedgerError, match="table 'tool_data' has columns station, serial"):
        WearLedger(other)


def test_the_plant_view_keeps_the_newest_word_of_a_tool_and_reads_older_replies() -> None:
    with_data = {
        "station": "st1",
        "ledger": "/a/wear.sqlite",
        "host": "line-a",
        "tools": [
            {
                "tool_id": 7, "runs": 2, "total_intensity": 3.0, "intensity_per_run": 1.5,
                "last_service_ns": None, "last_service_note": None, "runs_since_service": 2,
                "intensity_since_service": 3.0, "worst_runs": [], "stations": ["st1"],
                "controller": {
                    "station": "st1", "tool_serial": "B1234567", "controller_serial": None,
                    "tightenings": 10, "tightenings_since_service": 2,
                    "last_calibration_ns": None, "last_service_ns": None,
                    "calibration_value_nm": None, "tool_type": None, "tool_model": None,
                    "controller_software": None, "received_ns": T0_NS,
                },
            }
        ],
    }  # fmt: skip
    older = json.loads(json.dumps(with_data))  # a recorder of a ledger before tool data
    older.update(station="st3", ledger="/b/wear.sqlite", host="line-b")
    del older["tools"][0]["controller"]
    older["tools"][0]["stations"] = ["st3"]
    replies = [parse_reply(json.dumps(r).encode()) for r in (with_data, older)]
    assert replies[1].tools[0].controller is None
    (seven,) = merge(replies)
    assert seven.runs == 4 and seven.stations == ["st1", "st3"]
    assert seven.controller is not None and seven.controller.tool_serial == "B1234567"
