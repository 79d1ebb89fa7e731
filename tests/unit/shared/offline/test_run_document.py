"""A recorded run as the line's page draws it: its figures are the recording's.

Runs written by the real recorder (:func:`~tests.benchmarks.run_recordings.record_runs`,
3000 samples a run) and by the recorder's own MCAP sink (what a run holds beyond them: a
final stage's commands, a decision on no usable torque, lost preloads, the tool's own
clock, a controller's steps), read back with :func:`read_run_files` and checked against
the file read independently with mcap's own reader.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np
from mcap.reader import make_reader

from shared.contract import (
    JudgedFigure,
    ResultStep,
    StageDecision,
    StopDecision,
    encode,
)
from shared.offline.post_mortem import (
    MAX_POINTS,
    drawn_indices,
    read_run,
    read_run_files,
    run_document,
)
from shared.recordings import classify, file_path
from shared.recordings.mcap import McapSink
from tests.benchmarks.run_recordings import record_runs
from tests.support import factories

T0_NS = factories.T0
MS_NS = factories.MS


def _independent(path: Path, topic: str) -> list[dict[str, Any]]:
    """Every message of ``topic`` in ``path`` as JSON, by mcap's indexed reader."""
    with path.open("rb") as handle:
        reader = make_reader(handle)
        return [json.loads(message.data) for _, _, message in reader.iter_messages([topic])]


def test_a_recorded_run_s_document_holds_the_recording_s_figures(tmp_path: Path) -> None:
    recordings = record_runs(tmp_path, 2, 3000)
    path = sorted(recordings.glob("st1/*/st1_run2_*.mcap"))[0]
    document = run_document(read_run(path))
    json.dumps(document, allow_nan=False)  # JSON a browser parses: no NaN anywhere

    samples = [s for s in _independent(path, "boltwatch/st1/samples") if s["run_id"] == 2]
    assert document["samples"] == document["drawn"] == len(samples) == 3000
    series = document["series"]
    assert series["torque_nm"] == [s["torque_nm"] for s in samples]
    assert series["angle_deg"] == [s["angle_deg"] for s in samples]
    assert series["force_n"] == [s["force_n"] for s in samples]
    t0_ns = samples[0]["time_ns"]
    assert document["clock"] == "receive"  # these samples carry no clock of their own
    assert series["time_s"] == [round((s["time_ns"] - t0_ns) / 1e9, 6) for s in samples]
    assert document["last"]["torque_nm"] == samples[-1]["torque_nm"]

    (result,) = _independent(path, "boltwatch/st1/results")
    for figure in ("final_torque_nm", "final_angle_deg", "final_force_n"):
        assert document["result"][figure] == result[figure]
    assert (document["result"]["result"], document["result"]["part_id"]) == (
        result["result"],
        result["part_id"],
    )
    events = _independent(path, "boltwatch/st1/events")
    assert [e["index"] for e in document["events"]] == [e["index"] for e in events]
    assert [e["peak_torque_nm"] for e in document["events"]] == [
        e["peak_torque_nm"] for e in events
    ]
    by_time = {s["time_ns"]: s for s in samples}
    for drawn, event in zip(document["events"], events, strict=True):  # at the peak's sample
        assert drawn["angle_deg"] == by_time[event["time_ns"]]["angle_deg"]
    assert len(document["plateaus"]) == len(events)
    (decision,) = _independent(path, "boltwatch/st1/decision")
    assert document["decisions"][0]["reason"] == decision["reason"] == "plateau_closest"
    assert document["decisions"][0]["torque_nm"] == decision["torque_nm"]
    assert document["target"]["force_n"] == 56000.0  # the file's program record
    assert document["complete"] is True and document["files"] == [path.name]


def _record(path: Path, messages: list[tuple[str, Any]], metadata: dict[str, Any]) -> Path:
    with McapSink(path, metadata, 1, T0_NS) as sink:
        for topic, message in messages:
            sink.write(classify(f"boltwatch/st1/{topic}", encode(message), message.time_ns))
    return path


def _staged_run(samples: int = 200) -> list[tuple[str, Any]]:
    """A torque-only staged run on the tool's own clock (from 5 s), a lost preload, a final
    stage, a pulse, and a decision on a torque that was not usable."""
    messages: list[tuple[str, Any]] = []
    for n in range(samples):
        force = None if n % 10 == 3 else 10_000.0 + n
        messages.append(
            ("samples", factories.sample(1, n, torque_nm=n * 1.0, angle_deg=n * 0.5,
                                         force_n=force, time_s=5.0 + n / 1000))
        )  # fmt: skip
    messages.append(("events", factories.event(1, 1, time_ns=T0_NS + 40 * MS_NS, time_s=0.04)))
    final = StageDecision(
        "st1", 1, T0_NS + 120 * MS_NS, 0.12, "final", "below_switch_point", "", 120.0, 0,
        T0_NS + 120 * MS_NS,
    )  # fmt: skip
    pulse = StageDecision(
        "st1", 1, T0_NS + 180 * MS_NS, 0.18, "pulse", "lost_drop", "", 180.0, 1, T0_NS + 180 * MS_NS
    )
    messages += [("stage", final), ("stage", pulse)]
    decision = StopDecision(
        "st1", 1, T0_NS + 190 * MS_NS, 0.19, "input_fault", "torque not finite", math.nan,
        None, None, T0_NS + 190 * MS_NS,
    )  # fmt: skip
    messages.append(("decision", decision))
    return messages


def test_marks_sit_on_their_samples_and_nothing_is_nan(tmp_path: Path) -> None:
    path = _record(tmp_path / "run.mcap", _staged_run(), {"program": {"target_torque_nm": "150"}})
    document = run_document(read_run(path))
    json.dumps(document, allow_nan=False)
    assert document["clock"] == "sample"  # the tool's own clock, from the run's first sample
    assert document["series"]["time_s"][:3] == [0.0, 0.001, 0.002]
    forces = document["series"]["force_n"]
    assert forces[3] is None and forces[4] == 10_004.0  # a sample that came without one
    (event,) = document["events"]
    assert (event["time_s"], event["angle_deg"]) == (0.04, 20.0)  # sample 40's
    assert [
        (s["command"], s["time_s"], s["angle_deg"], s["pulse"]) for s in document["stages"]
    ] == [
        ("final", 0.12, 60.0, 0),
        ("pulse", 0.18, 90.0, 1),
    ]
    (decision,) = document["decisions"]
    assert (decision["reason"], decision["torque_nm"], decision["angle_deg"]) == (
        "input_fault",
        None,
        95.0,
    )
    assert document["target"]["torque_nm"] == 150.0 and document["result"] is None


def test_a_controller_s_run_carries_its_steps_and_its_own_windows(tmp_path: Path) -> None:
    steps = [
        ResultStep("Tightening 1.1", "", None, None, "OK"),
        ResultStep("Tightening 1.2", "TF Torque", 25.0, 25.3, "NOK"),
    ]
    result = factories.result(
        1, source="controller", steps=steps, result="NOK", nok_reasons="torque high",
        final_torque_nm=JudgedFigure(25.3, 23.0, 25.2, "high"),
    )  # fmt: skip
    messages = [("samples", factories.sample(1, n, torque_nm=n * 0.25)) for n in range(110)]
    path = _record(tmp_path / "run.mcap", [*messages, ("results", result)], {})
    document = run_document(read_run(path))
    assert document["target"] is None  # the file's program record is the station file's
    controller = document["controller"]
    assert controller["torque_window_nm"] == [23.0, 25.2] and controller["torque_target_nm"] == 25.0
    assert [s["function"] for s in document["result"]["steps"]] == ["", "TF Torque"]
    assert document["result"]["nok_reasons"] == "torque high"


def test_a_long_run_is_thinned_keeping_every_peak_and_drop() -> None:
    torque = np.sin(np.arange(50_000) / 300.0)
    torque[31_337], torque[12_345] = 9.0, -9.0
    kept = drawn_indices(torque)
    assert len(kept) <= MAX_POINTS + 2
    assert {0, 12_345, 31_337, 49_999} <= set(kept.tolist())
    assert np.all(np.diff(kept) > 0)
    assert drawn_indices(torque[:3000]).tolist() == list(range(3000))  # a tightening: whole


def test_a_run_in_parts_is_read_from_every_file_and_a_broken_one_is_named(
    tmp_path: Path,
) -> None:
    messages = [("samples", factories.sample(4, n, torque_nm=float(n))) for n in range(300)]
    first = file_path(tmp_path, "st1", 4, T0_NS)
    second = file_path(tmp_path, "st1", 4, T0_NS + 150 * MS_NS, part=2)
    first.parent.mkdir(parents=True)
    _record(first, messages[:150], {})
    _record(second, messages[150:], {})
    run = read_run_files([first, second], 4)
    assert [s.sequence for s in run.samples] == list(range(300))
    assert run.sources == [first, second] and run.complete
    broken = second.with_name("st1_run4_000001_part3.mcap")
    broken.write_bytes(b"not an MCAP file at all")
    run = read_run_files([first, second, broken], 4)
    assert len(run.samples) == 300 and not run.complete
    assert f"{broken}: not an MCAP file" in run.state and "left out" in run.state
    document = run_document(run)
    assert document["files"] == [first.name, second.name, broken.name]
