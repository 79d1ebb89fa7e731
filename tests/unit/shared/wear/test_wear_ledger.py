"""The wear ledger: eq. 69 totals, counted once per run across restarts, services, readers."""

from __future__ import annotations

import sqlite3
import threading
from dataclasses import replace
from pathlib import Path

import pytest

from services.cli.main import main
from shared.contract import RunSummary
from shared.errors import InputError
from shared.wear import APPLICATION_ID, LEDGER_VERSION, WearLedger, ledger_path
from shared.wear import COLUMNS as LEDGER_COLUMNS
from shared.wear import CONTRACT_LIMITS as LIMITS
from tests.support import factories

T0_NS = 1_700_000_000_000_000_000
S_NS = 1_000_000_000


def summary(run_id: int, intensity: float, tool_id: int = 7, station: str = "st1") -> RunSummary:
    """A half-second run ended ``run_id`` seconds after T0."""
    ended = T0_NS + run_id * S_NS
    return factories.summary(
        run_id,
        station=station,
        tool_id=tool_id,
        events=4,
        process_intensity=intensity,
        samples=500,
        started_ns=ended - S_NS // 2,
        ended_ns=ended,
    )


def test_totals_follow_eq_69_and_worst_runs_lead(tmp_path: Path) -> None:
    with WearLedger(tmp_path / "wear.sqlite") as ledger:
        for run_id, intensity in enumerate([0.5, 2.0, 1.0, 0.25], start=1):
            assert ledger.add_run(summary(run_id, intensity), T0_NS, LIMITS)
        assert ledger.add_run(summary(1, 9.0, tool_id=8, station="st2"), T0_NS, LIMITS)
        wear = ledger.tool(7)
    assert (wear.runs, wear.total_intensity, wear.intensity_per_run) == (4, 3.75, 3.75 / 4)
    worst = [(r.run_id, r.process_intensity) for r in wear.worst_runs]
    assert worst == [(2, 2.0), (3, 1.0), (1, 0.5)]
    assert wear.last_service_ns is None
    assert (wear.runs_since_service, wear.intensity_since_service) == (4, 3.75)


def test_a_loosening_adds_its_intensity_but_is_none_of_the_tools_tightenings(
    tmp_path: Path,
) -> None:
    with WearLedger(tmp_path / "wear.sqlite") as ledger:
        for run_id, intensity in enumerate([0.5, 2.0], start=1):
            assert ledger.add_run(summary(run_id, intensity), T0_NS, LIMITS)
        loosening = replace(summary(3, 1.5), operation="loosening")
        assert ledger.add_run(loosening, T0_NS, LIMITS)
        assert not ledger.add_run(loosening, T0_NS, LIMITS)  # once, as any run
        wear = ledger.tool(7)
        interval = ledger.since_service(7)
    assert (wear.runs, wear.loosenings, wear.total_intensity) == (2, 1, 4.0)
    assert wear.intensity_per_run == 4.0 / 3  # of every run
    assert (wear.runs_since_service, wear.intensity_since_service) == (2, 4.0)
    assert (interval.runs, interval.intensity) == (2, 4.0)
    assert [r.run_id for r in wear.worst_runs] == [2, 3, 1]


#: the runs table as boltwatch made it before a run's operation (ledger version 2)
RUNS_OF_VERSION_2 = """
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


def test_a_ledger_made_before_operations_is_read_as_tightenings_and_migrated(
    tmp_path: Path,
) -> None:
    path = tmp_path / "wear.sqlite"
    db = sqlite3.connect(path)
    db.execute(f"PRAGMA application_id = {APPLICATION_ID}")
    db.execute("PRAGMA user_version = 2")
    db.execute("PRAGMA journal_mode=WAL")
    db.executescript(RUNS_OF_VERSION_2)
    for run_id, intensity in ((1, 1.0), (2, 2.0)):
        s = summary(run_id, intensity)
        db.execute(
            "INSERT INTO runs VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?)",
            (s.station, s.run_id, s.tool_id, s.program_id, s.tool_state, s.stop_reason,
             s.events, s.process_intensity, s.started_ns, s.ended_ns, T0_NS),
        )  # fmt: skip
    db.commit()
    db.close()
    with WearLedger(path, read_only=True) as reader:  # `boltwatch wear` on the old ledger
        seven = reader.tool(7)
    assert (seven.runs, seven.loosenings, seven.total_intensity) == (2, 0, 3.0)

    with WearLedger(path) as ledger:  # a writer opens it: the column is added, nothing lost
        assert ledger.add_run(replace(summary(3, 4.0), operation="loosening"), T0_NS, LIMITS)
        seven = ledger.tool(7)
    assert (seven.runs, seven.loosenings, seven.total_intensity) == (2, 1, 7.0)
    db = sqlite3.connect(path)
    try:
        assert db.execute("PRAGMA user_version").fetchone() == (LEDGER_VERSION,)
        columns = tuple(row[1] for row in db.execute("PRAGMA table_info(runs)"))
        assert columns == LEDGER_COLUMNS["runs"]
        operations = db.execute("SELECT run_id, operation FROM runs ORDER BY run_id").fetchall()
    finally:
        db.close()
    assert operations == [(1, "tightening"), (2, "tightening"), (3, "loosening")]


def test_a_repeated_summary_or_a_restart_never_counts_twice(tmp_path: Path) -> None:
    path = tmp_path / "wear.sqlite"
    with WearLedger(path) as ledger:
        assert ledger.add_run(summary(1, 1.0), T0_NS, LIMITS)
        assert not ledger.add_run(summary(1, 1.0), T0_NS + 1, LIMITS)  # redelivered
    with WearLedger(path) as ledger:  # the recorder restarted and sees run 1 again
        assert not ledger.add_run(summary(1, 1.0), T0_NS + 2, LIMITS)
        assert ledger.add_run(summary(2, 0.5), T0_NS + 3, LIMITS)
        assert (ledger.tool(7).runs, ledger.tool(7).total_intensity) == (2, 1.5)


def test_a_service_restarts_the_interval_and_keeps_history(tmp_path: Path) -> None:
    with WearLedger(tmp_path / "wear.sqlite") as ledger:
        ledger.add_run(summary(1, 1.0), T0_NS, LIMITS)
        ledger.add_run(summary(2, 2.0), T0_NS, LIMITS)
        ledger.record_service(7, "new socket", T0_NS + 2 * S_NS + 1)  # after run 2 ended
        ledger.add_run(summary(3, 0.5), T0_NS, LIMITS)
        wear = ledger.tool(7)
        assert ledger.tool_ids() == [7]
    assert (wear.runs, wear.total_intensity) == (3, 3.5)
    assert (wear.runs_since_service, wear.intensity_since_service) == (1, 0.5)
    assert (wear.last_service_ns, wear.last_service_note) == (T0_NS + 2 * S_NS + 1, "new socket")


def test_a_reader_sees_consistent_lines_while_the_recorder_writes(tmp_path: Path) -> None:
    path = tmp_path / "wear.sqlite"
    runs = 200
    writer = WearLedger(path)
    seen: list[tuple[int, float]] = []
    errors: list[BaseException] = []
    done = threading.Event()

    def read() -> None:
        try:
            with WearLedger(path, read_only=True) as reader:
                while not done.is_set():
                    wear = reader.tool(7)
                    seen.append((wear.runs, wear.total_intensity))
        except BaseException as err:
            errors.append(err)

    thread = threading.Thread(target=read)
    thread.start()
    try:
        for run_id in range(1, runs + 1):
            writer.add_run(summary(run_id, 1.0), T0_NS, LIMITS)
    finally:
        done.set()
        thread.join(10)
        writer.close()
    assert not errors
    assert all(total == float(count) for count, total in seen)  # each line is one snapshot
    assert [count for count, _ in seen] == sorted(count for count, _ in seen)
    with WearLedger(path, read_only=True) as reader:
        assert reader.tool(7).runs == runs


def test_cli_prints_the_table_and_records_services(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    with WearLedger(ledger_path(tmp_path)) as ledger:
        ledger.add_run(summary(1, 1.5), T0_NS, LIMITS)
    assert main(["wear", "--recordings", str(tmp_path)]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[0].split()[:5] == ["tool", "serial", "runs", "I_total", "I/run"]
    assert lines[1].split()[:5] == ["7", "-", "1", "1.5", "1.5"]  # no controller said a serial
    service = ["wear", "service", "7", "--note", "new socket"]
    assert main([*service, "--recordings", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert "recorded a service of tool 7" in out and "(new socket)" in out
    assert main(["wear", "service", "--recordings", str(tmp_path)]) == 2
    assert main(["wear", "--recordings", str(tmp_path / "nowhere")]) == 2
    assert "no wear ledger here" in capsys.readouterr().err


def test_read_only_needs_an_existing_ledger(tmp_path: Path) -> None:
    with pytest.raises(InputError, match="no wear ledger here"):
        WearLedger(tmp_path / "wear.sqlite", read_only=True)


def test_a_tool_is_one_asset_across_stations_and_a_station_lists_its_tools(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    with WearLedger(ledger_path(tmp_path)) as ledger:
        ledger.add_run(summary(1, 1.0, tool_id=7, station="st1"), T0_NS, LIMITS)
        ledger.add_run(summary(2, 2.0, tool_id=7, station="st2"), T0_NS, LIMITS)  # tool moved
        ledger.add_run(summary(3, 4.0, tool_id=8, station="st2"), T0_NS, LIMITS)
        # the same run id at another station
        ledger.add_run(summary(1, 8.0, tool_id=9, station="st3"), T0_NS, LIMITS)
        assert ledger.tool_ids() == [7, 8, 9]
        assert ledger.tool_ids(station="st1") == [7]
        assert [t.tool_id for t in ledger.tools(station="st2")] == [7, 8]
        assert ledger.tools(station="nowhere") == []
        seven = ledger.tool(7)
    assert (seven.runs, seven.total_intensity, seven.stations) == (2, 3.0, ["st1", "st2"])

    assert main(["wear", "--recordings", str(tmp_path), "--station", "st1"]) == 0
    table = capsys.readouterr().out.splitlines()
    assert "stations" in table[0]
    (line,) = table[1 : table.index("")]  # the ledger's table; the forecast's below it
    assert line.split()[:4] == ["7", "-", "2", "3"]  # whole totals, st1 and st2
    assert "st1,st2" in line
    assert main(["wear", "--recordings", str(tmp_path), "--station", "st9"]) == 0
    assert "no runs at station st9" in capsys.readouterr().out
