"""An imported CS351 run gets its TighteningResult from the controller's own values.

The real runs shipped in ``tests/data/cs351-real-runs`` (all OK by their
controller and the data set's labels) are imported; the result on
``boltwatch/cs351/results`` is read back from the MCAP file with ``json``
alone and checked against its schema. A copy of a real run that the
controller judged NOK (its last step NOK, its torque above the step's
``MFs TorqueMax``) gives NOK; a copy without the controller's verdict is
judged by its windows.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from tests.support.imported_runs import import_runs, messages_by_topic, recording_of
from tests.support.paths import PROJECT_REAL_RUNS

RUNS = sorted(PROJECT_REAL_RUNS.glob("Ch_*.json"))


def result_of(recordings: Path, source: Path) -> dict[str, Any]:
    (result,) = messages_by_topic(recording_of(recordings, source))["results"]
    return result


def function(step: dict[str, Any], name: str) -> dict[str, Any]:
    return next(f for f in step["tightening functions"] if f["name"] == name)


def test_every_real_run_gets_the_controllers_verdict_its_windows_and_steps(
    tmp_path: Path,
) -> None:
    assert import_runs(RUNS, tmp_path) == 0
    for source in RUNS:
        document = json.loads(source.read_text())
        result = result_of(tmp_path, source)
        (summary,) = messages_by_topic(recording_of(tmp_path, source))["runs"]
        last = document["tightening steps"][-1]
        assert result["result"] == document["result"] == "OK"
        assert result["nok_reasons"] == ""
        assert result["source"] == "import"
        assert result["tightening_id"] == result["run_id"] == document["cycle"]
        assert result["part_id"] == document["id code"]
        assert result["batch_counter"] is None  # the controller keeps no batch (-1)
        assert result["program_name"] == document["prg name"]
        assert result["final_torque_nm"] == {
            "value": function(last, "TF Torque")["act"],
            "min": function(last, "MF TorqueMin")["nom"],  # 1.2 to 1.6 Nm
            "max": function(last, "MFs TorqueMax")["nom"],
            "status": "ok",
        }
        assert result["final_angle_deg"] == {
            "value": function(last, "MF AngleMin")["act"],
            "min": function(last, "MF AngleMin")["nom"],
            "max": function(last, "MFs AngleMax")["nom"],
            "status": "ok",
        }
        assert result["final_force_n"]["status"] == "not_judged"  # no preload measured
        assert [
            (s["name"], s["function"], s["nominal"], s["actual"], s["status"])
            for s in result["steps"]
        ] == [
            (
                s["name"],
                s["last cmd"],
                function(s, s["last cmd"])["nom"],
                function(s, s["last cmd"])["act"],
                s["result"],
            )
            for s in document["tightening steps"]
        ]
        assert (result["events"], result["process_intensity"]) == (
            summary["events"],
            summary["process_intensity"],
        )
        assert result["stop_reason"] is None  # the controller stopped its tool


def nok_copy(source: Path, folder: Path) -> Path:
    """A real run as its controller would report a torque above the last step's window."""
    document = json.loads(source.read_text())
    last = document["tightening steps"][-1]
    function(last, "TF Torque")["act"] = 1.71
    last["result"] = "NOK"
    last["quality code"] = "   12"
    document["result"] = "NOK"
    document["cycle"] += 9_000_000
    copy = folder / f"nok_{source.name}"
    copy.write_text(json.dumps(document))
    return copy


def test_a_run_the_controller_judged_nok_is_nok_with_its_step_and_figure(tmp_path: Path) -> None:
    copy = nok_copy(RUNS[0], tmp_path)
    assert import_runs([copy], tmp_path / "recordings") == 0
    result = result_of(tmp_path / "recordings", copy)
    assert result["result"] == "NOK"
    assert result["final_torque_nm"]["status"] == "high"
    assert result["nok_reasons"] == (
        "step 'Tightening 1.4' NOK (quality code 12); torque high: 1.71 Nm, window 1.2 to 1.6 Nm"
    )
    assert [s["status"] for s in result["steps"]] == ["OK", "OK", "OK", "NOK"]


def test_without_the_controllers_verdict_the_windows_decide(tmp_path: Path) -> None:
    copy = nok_copy(RUNS[0], tmp_path)
    document = json.loads(copy.read_text())
    del document["result"]
    copy.write_text(json.dumps(document))
    ok = json.loads(RUNS[1].read_text())
    del ok["result"]
    ok_copy = tmp_path / "no_verdict_ok.json"
    ok_copy.write_text(json.dumps(ok))
    assert import_runs([copy, ok_copy], tmp_path / "recordings") == 0
    assert result_of(tmp_path / "recordings", copy)["result"] == "NOK"
    assert result_of(tmp_path / "recordings", ok_copy)["result"] == "OK"
