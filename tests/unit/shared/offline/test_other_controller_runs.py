"""Runs of another controller of the CS351's family: text identifiers, loosenings, resolution.

A cordless nutrunner of the same family writes the same JSON layout with its
tool serial and batch number as text, and exports its loosenings too. Its
runs are made from the real CS351 runs (tests/support/other_controller_runs.py).
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from mcap.reader import make_reader

from shared.offline.controller_import import read_controller_run
from shared.offline.post_mortem import build_figure, read_run
from shared.offline.report import ResultFilter, read_results
from shared.stickslip import EventFigures, PredictorCore, PredictorSettings
from shared.wear import WearLedger, ledger_path
from tests.support.imported_runs import import_runs, messages_by_topic
from tests.support.other_controller_runs import (
    OTHER_SERIAL,
    SOURCE_RUN,
    at_resolution,
    loosening_of,
    with_text_identifiers,
)
from tests.support.paths import HANDBOOK_REAL_RUNS, PROJECT_REAL_RUNS

#: a real class-2 run (1400 samples)
CLASS_2_RUN = "Ch_000001621524.json"


def _recording(recordings: Path, run_id: int) -> Path:
    (path,) = recordings.glob(f"cs351/*/cs351_run{run_id}_*.mcap")
    return path


def _metadata(path: Path) -> dict[str, dict[str, str]]:
    with path.open("rb") as handle:
        return {record.name: record.metadata for record in make_reader(handle).iter_metadata()}


def test_a_tool_serial_and_batch_number_written_as_text_are_read(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = with_text_identifiers(tmp_path / "in")
    run = read_controller_run(path)
    assert run.tool_id == int(OTHER_SERIAL)
    assert run.verdict.batch["batch_number"] == 85

    recordings = tmp_path / "recordings"
    assert import_runs([path], recordings) == 0, capsys.readouterr().err
    recording = _recording(recordings, run.run_id)
    messages = messages_by_topic(recording)
    (controller,) = messages["controller"]
    assert (controller["tool_id"], controller["batch_number"]) == (520000905, 85)
    assert _metadata(recording)["controller"]["tool serial"] == OTHER_SERIAL  # as written


@pytest.mark.parametrize(
    ("key", "value", "expected"),
    [
        (
            "tool serial",
            "GP1010003",
            "'tool serial': expected an integer (as a number or as its digits), got str "
            "'GP1010003'",
        ),
        (
            "tool serial",
            "",
            "'tool serial': expected an integer (as a number or as its digits), got str ''",
        ),
        ("tool serial", "-5", "'tool serial': expected a number from 0 up, got -5"),
        (
            "batch nr",
            "eighty-five",
            "'batch nr': expected an integer (as a number or as its digits), got str 'eighty-five'",
        ),
        ("batch nr", 8.5, "'batch nr': expected an integer, got float 8.5"),
    ],
)
def test_identifiers_that_cannot_be_read_as_numbers_are_refused_naming_the_key(
    tmp_path: Path, key: str, value: object, expected: str, capsys: pytest.CaptureFixture[str]
) -> None:
    document = json.loads(SOURCE_RUN.read_text())
    document[key] = value
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(document))
    assert import_runs([path], tmp_path / "recordings") == 2
    (line,) = capsys.readouterr().err.strip().splitlines()
    assert line.startswith(f"boltwatch import: {path}: "), line
    assert expected in line, line


def test_a_loosening_is_recorded_as_a_loosening_and_counted_as_none_of_the_tightenings(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    tightening = with_text_identifiers(tmp_path / "in")
    loosening = loosening_of(tmp_path / "in")
    assert read_controller_run(tightening).operation == "tightening"
    assert read_controller_run(loosening).operation == "loosening"
    recordings = tmp_path / "recordings"

    assert import_runs([tightening, loosening], recordings) == 0, capsys.readouterr().err

    run = read_controller_run(loosening)
    recording = _recording(recordings, run.run_id)
    messages = messages_by_topic(recording)
    (summary,) = messages["runs"]
    (controller,) = messages["controller"]
    assert summary["operation"] == controller["operation"] == "loosening"
    assert summary["target_torque_nm"] is None  # an angle target: no torque to stop at
    assert "results" not in messages  # not a tightening: no tightening result
    assert _metadata(recording)["controller"]["operation"] == "loosening"
    # its replay sees the load on the tool whichever way it turns
    assert summary["reached_torque_nm"] == pytest.approx(1.408, abs=0.01)  # the breakaway
    tightening_summary = messages_by_topic(
        _recording(recordings, read_controller_run(tightening).run_id)
    )["runs"][0]
    assert tightening_summary["operation"] == "tightening"

    # the tightening statistics (report, Cpk) hold the tightening only
    read = read_results(ResultFilter(stations=[("cs351", recordings)]))
    assert read.results == 1
    # the wear ledger: one tightening, one loosening; both runs' vibration in the tool's total
    with WearLedger(ledger_path(recordings), read_only=True) as ledger:
        tool = ledger.tool(int(OTHER_SERIAL))
    assert (tool.runs, tool.loosenings, tool.runs_since_service) == (1, 1, 1)
    assert summary["process_intensity"] > 0.0  # the loosening vibrated the tool too
    assert tool.total_intensity == pytest.approx(
        tightening_summary["process_intensity"] + summary["process_intensity"]
    )

    # its post-mortem draws the torque as the replay saw it: its magnitude
    figure = build_figure(read_run(recording))
    lines = {line.get_label(): line for line in figure.axes[0].get_lines()}
    assert float(np.min(lines["torque |T| (a loosening)"].get_ydata())) >= 0.0
    assert "a loosening: torque drawn as its magnitude" in figure.get_suptitle()


def _replay_drops(path: Path) -> list[float]:
    """The drops of the events ``boltwatch import`` records for the run at ``path``."""
    from shared.offline.controller_import.controller_replay import replay_run

    replay = replay_run("cs351", read_controller_run(path))
    return [m.torque_drop_nm for _, topic, m in replay.outputs if topic == "events"]


def test_a_drop_the_signal_cannot_resolve_is_not_an_event(tmp_path: Path) -> None:
    """A real run written to 0.01 Nm (a coarser tool): six flickers of two steps near its
    end were events; a drop must span more than three steps of the signal's resolution."""
    coarse = at_resolution(tmp_path, step_nm=0.01, source=PROJECT_REAL_RUNS / CLASS_2_RUN)
    drops = _replay_drops(coarse)
    assert drops, "the run's stick-slip is still found"
    assert min(drops) > 0.035, drops
    assert read_controller_run(coarse).torque_resolution_nm == pytest.approx(0.01)


def _core_events(path: Path) -> list[tuple[float, float]]:
    """(time, drop) of the events the core finds on the run with no resolution given."""
    run = read_controller_run(path)
    core = PredictorCore(
        PredictorSettings(
            target_torque_nm=run.final_torque_nominal_nm, has_force=False, advisory=True
        )
    )
    out: list[tuple[float, float]] = []
    for row in zip(
        run.run_time_s, run.torque_nm, [math.nan] * len(run), run.angle_deg, strict=True
    ):
        out += [
            (o.time_s, o.torque_drop_nm) for o in core.update(*row) if isinstance(o, EventFigures)
        ]
    return out


def test_the_real_cs351_runs_keep_every_event(tmp_path: Path) -> None:
    """At the CS351's own resolution (0.001 Nm) the floor is far under its smallest events."""
    folders = [PROJECT_REAL_RUNS] + ([HANDBOOK_REAL_RUNS] if HANDBOOK_REAL_RUNS.is_dir() else [])
    for path in sorted(p for folder in folders for p in folder.glob("Ch_*.json")):
        drops = _replay_drops(path)
        assert drops == [drop for _, drop in _core_events(path)], path.name
        assert read_controller_run(path).torque_resolution_nm == pytest.approx(0.001), path.name
