"""What imported runs are for: the predictor's view, the wear ledger, the controller's result.

Real CS351 runs (the four shipped ones) imported with ``boltwatch import``
and read back with the mcap reader and ``json`` alone: each recording holds
the predictor's events, intensities, its advisory decision and a run
summary, on the channels and with the schemas of a live run, and the same
events ``boltwatch predict`` finds on the run's trace CSV; the controller's
own result (each step's name, OK/NOK, nominal and actual values) is on
``boltwatch/<st>/controller``; the runs count in the wear ledger under the
controller's tool serial, never twice.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from services.cli.main import main
from shared.contract import ControllerResult, json_schema, read_trace
from shared.offline.controller_import import read_controller_run
from shared.wear import WearLedger
from tests.support.imported_runs import import_runs, messages_by_topic, recording_of
from tests.support.paths import PROJECT_REAL_RUNS

RUNS = sorted(PROJECT_REAL_RUNS.glob("Ch_*.json"))
TOOL_SERIAL = 955000040  # every shipped run's ``tool serial``


def test_an_imported_run_holds_the_predictor_output_of_a_live_run(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    recordings, csv_dir = tmp_path / "recordings", tmp_path / "csv"
    assert import_runs(RUNS, recordings) == 0
    assert main(["import", *map(str, RUNS), "--csv", str(csv_dir)]) == 0
    capsys.readouterr()
    for source in RUNS:
        run = read_controller_run(source)
        topics = messages_by_topic(recording_of(recordings, source))
        events, intensities = topics["events"], topics["intensity"]
        (summary,) = topics["runs"]
        (decision,) = topics["decision"]  # every shipped run reaches its 1.4 Nm

        assert len(events) == len(intensities) == summary["events"]
        assert [e["index"] for e in events] == list(range(1, len(events) + 1))
        assert summary["process_intensity"] == pytest.approx(
            events[-1]["process_intensity"] if events else 0.0
        )
        assert summary["stop_reason"] is None  # the controller stopped the tool
        assert summary["tool_id"] == TOOL_SERIAL and summary["samples"] == len(run)
        assert summary["target_torque_nm"] == 1.4 == run.final_torque_nominal_nm
        assert summary["reached_torque_nm"] == run.final_torque_actual_nm  # the controller's
        assert summary["target_force_n"] is None and summary["reached_force_n"] is None
        assert decision["advisory"] is True  # decided on a replay, never acted on

        # the same core as `boltwatch predict`, on the trace CSV `import --csv` wrote; a
        # replay is advisory, so it also reports the events detected after its decision
        csv = csv_dir / f"{source.stem}.csv"
        assert main(["predict", str(csv), "--target-torque", "1.4"]) == 0
        predicted = [json.loads(line) for line in capsys.readouterr().out.splitlines()]
        (stop,) = [p for p in predicted if p["type"] == "stop"]
        assert decision["reason"] == stop["reason"]
        assert decision["time_s"] == pytest.approx(stop["time_s"], abs=1e-6)
        before_stop = [
            event
            for event, intensity in zip(events, intensities, strict=True)
            if intensity["time_ns"] <= decision["time_ns"]  # detected by the deciding sample
        ]
        expected = [p for p in predicted if p["type"] == "event"]
        assert [e["time_s"] for e in before_stop] == pytest.approx(
            [p["time_s"] for p in expected], abs=1e-6
        )
        assert [e["peak_torque_nm"] for e in before_stop] == pytest.approx(
            [p["peak_torque_nm"] for p in expected], abs=1e-4
        )

    path = recording_of(recordings, RUNS[0])  # the post-mortem shows the predictor's view
    assert main(["inspect", str(path), "--out", str(tmp_path / "run.png")]) == 0
    events = messages_by_topic(path)["events"]
    assert f"run 1596334, 624 samples, {len(events)} stick-slip events" in capsys.readouterr().out


def test_inspect_asked_for_a_run_the_file_lacks_names_the_runs_it_has(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert import_runs(RUNS[:1], tmp_path) == 0
    path = recording_of(tmp_path, RUNS[0])
    capsys.readouterr()
    assert main(["inspect", str(path), "--run", "5", "--out", str(tmp_path / "x.png")]) == 2
    (line,) = capsys.readouterr().err.splitlines()
    assert line == f"boltwatch inspect: {path}: no samples of run 5 (runs in the file: 1596334)"


def test_imported_runs_count_in_the_wear_ledger_once_by_station_and_run(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    recordings = tmp_path / "recordings"
    assert import_runs(RUNS[:2], recordings) == 0
    assert import_runs([RUNS[1], *RUNS[1:], RUNS[3]], recordings) == 0  # overlaps, repeats
    assert import_runs(RUNS, recordings) == 0  # all again
    summaries = [messages_by_topic(recording_of(recordings, s))["runs"][0] for s in RUNS]
    with WearLedger(recordings / "wear.sqlite", read_only=True) as ledger:
        (tool,) = ledger.tools()
        assert tool.tool_id == TOOL_SERIAL and tool.stations == ["cs351"]
        assert tool.runs == len(RUNS)
        assert tool.total_intensity == pytest.approx(sum(s["process_intensity"] for s in summaries))

    (recordings / "wear.sqlite").unlink()  # a ledger lost: the recordings still know
    for suffix in ("-wal", "-shm"):
        (recordings / f"wear.sqlite{suffix}").unlink(missing_ok=True)
    capsys.readouterr()
    assert import_runs(RUNS, recordings) == 0
    assert capsys.readouterr().out.splitlines()[-1].endswith(", 4 already there, 0 refused")
    with WearLedger(recordings / "wear.sqlite", read_only=True) as ledger:
        assert ledger.tool(TOOL_SERIAL).runs == len(RUNS)

    capsys.readouterr()
    assert main(["wear", "--recordings", str(recordings), "--json"]) == 0
    (line,) = json.loads(capsys.readouterr().out)
    assert (line["tool_id"], line["runs"]) == (TOOL_SERIAL, len(RUNS))


def test_the_controllers_own_result_is_recorded_on_its_channel(tmp_path: Path) -> None:
    assert import_runs(RUNS, tmp_path) == 0
    for source in RUNS:
        document = json.loads(source.read_text())
        (result,) = messages_by_topic(recording_of(tmp_path, source))["controller"]
        assert json_schema(ControllerResult)["title"] == "boltwatch.ControllerResult"
        assert result["run_id"] == document["cycle"] and result["tool_id"] == TOOL_SERIAL
        assert result["result"] == document["result"] == "OK"
        assert result["quality_code"] == document["quality code"].strip()
        assert result["part_id"] == document["id code"]
        assert result["torque_unit"] == "Nm"
        assert result["batch_number"] == document["batch nr"]
        assert result["batch_ok"] == document["batch OK"]
        steps = document["tightening steps"]
        assert result["torsion_release_samples"] == steps[-1]["graph"]["torsion release"]
        assert [s["name"] for s in result["steps"]] == [s["name"] for s in steps]
        assert [s["result"] for s in result["steps"]] == [s["result"] for s in steps]
        assert [s["samples"] for s in result["steps"]] == [
            len(s["graph"]["time values"]) for s in steps
        ]
        for recorded, step in zip(result["steps"], steps, strict=True):
            assert [(f["name"], f["nominal"], f["actual"]) for f in recorded["functions"]] == [
                (f["name"], f["nom"], f["act"]) for f in step["tightening functions"]
            ]


def test_import_csv_and_export_count_time_from_the_runs_first_sample(tmp_path: Path) -> None:
    document = json.loads(RUNS[0].read_text())
    for step in document["tightening steps"]:  # a controller whose clock starts at 2.5 s
        step["graph"]["time values"] = [t + 2.5 for t in step["graph"]["time values"]]
    late = tmp_path / "late.json"
    late.write_text(json.dumps(document))
    recordings = tmp_path / "recordings"

    assert main(["import", str(late), "--csv", str(tmp_path)]) == 0
    assert import_runs([late], recordings) == 0
    assert (
        main(["export", str(recording_of(recordings, late)), "--out", str(tmp_path / "e.csv")]) == 0
    )

    imported, exported = read_trace(tmp_path / "late.csv"), read_trace(tmp_path / "e.csv")
    assert imported.time_s[0] == exported.time_s[0] == 0.0
    assert list(imported.time_s) == pytest.approx(list(exported.time_s), abs=1e-6)
    assert list(imported.torque_nm) == pytest.approx(list(exported.torque_nm), abs=1e-4)
