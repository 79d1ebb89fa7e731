"""No message falsifies a figure: the wear ledger counts a run only within what its tool can take.

The bound (shared/wear/wear_bound.py): I_process ≤ (n_ss − 1) · T_lim² ·
f_s/2, with T_lim the program's max_torque_nm, n_ss ≤ samples/2 and the
samples within what the run's duration (and the program's max_time_s)
carries at 1 kHz. The probes (a negative intensity and 9e11 from
random frames on the ToolSensors id, a forged 1e15) are refused; real runs,
the shipped CS351 ones and the handbook's, are counted.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import pytest

from services.cli.main import main
from shared.config import load_station
from shared.contract import RunSummary
from shared.wear import F_SS_MAX_HZ, RefusedSummaryError, StationLimits, WearLedger, refusal
from tests.support import factories
from tests.support.live_recorder import write_station_file
from tests.support.paths import HANDBOOK_REAL_RUNS, PROJECT_REAL_RUNS

T0_NS = 1_700_000_000_000_000_000
S_NS = 1_000_000_000
T_LIM_NM = 320.0  # program 1 of config/station.toml


def simulated_run(**changes: Any) -> RunSummary:
    """A run of program 1 as the simulated station makes them (``make run``'s table)."""
    run: dict[str, Any] = {
        "run_id": 1795272478,
        "reached_force_n": 55.93e3,
        "reached_torque_nm": 201.0,
        "error_pct": -0.12,
        "events": 41,
        "process_intensity": 1.03e6,
        "samples": 1677,
        "started_ns": T0_NS,
        "ended_ns": T0_NS + 1_676_400_000,
    }
    return factories.summary(**{**run, **changes})


@pytest.fixture
def limits(tmp_path: Path) -> StationLimits:
    path = write_station_file(
        tmp_path / "station.toml", tmp_path / "recordings", listen=["tcp/127.0.0.1:1"]
    )
    return StationLimits([load_station(path)])


BOUND_41_EVENTS = 40 * T_LIM_NM**2 * F_SS_MAX_HZ  # 2.05e9

REFUSED: dict[str, tuple[dict[str, object], str]] = {
    # the probes that found it
    "negative (random frames)": ({"process_intensity": -2e9}, "is negative"),
    "9e11 (random frames)": ({"process_intensity": 9e11}, "beyond what 41 events can carry"),
    "forged 1e15": ({"process_intensity": 1e15}, "beyond what 41 events can carry"),
    "nan": ({"process_intensity": math.nan}, "not a finite number"),
    "inf": ({"process_intensity": math.inf}, "not a finite number"),
    # just beyond the bound
    "above the bound": ({"process_intensity": BOUND_41_EVENTS * 1.001}, "beyond"),
    "one event, some wear": ({"events": 1, "process_intensity": 1.0}, "beyond what 1 events"),
    # inconsistent in itself
    "more events than samples/2": ({"events": 900, "process_intensity": 1e6}, "900 events in"),
    "more samples than 1 kHz": ({"samples": 5000}, "more than 1000 Hz can carry"),
    "ended before it started": ({"ended_ns": T0_NS - 1}, "before it started"),
    "beyond max_time_s": (
        {"samples": 9000, "ended_ns": T0_NS + 9 * S_NS},
        "more than the program's max_time_s 6 s allows",
    ),
}


@pytest.mark.parametrize("case", list(REFUSED), ids=list(REFUSED))
def test_a_summary_beyond_its_bound_never_enters_the_ledger(
    case: str, limits: StationLimits, tmp_path: Path
) -> None:
    changes, why = REFUSED[case]
    summary = simulated_run(**changes)
    with WearLedger(tmp_path / "wear.sqlite") as ledger:
        with pytest.raises(RefusedSummaryError, match=why) as refused:
            ledger.add_run(summary, T0_NS, limits.of(summary))
        assert ledger.tool_ids() == []
    assert str(refused.value).startswith(f"run summary st1/run{summary.run_id} (tool 7) ")
    assert "\n" not in str(refused.value)


def test_true_runs_are_counted_up_to_the_bound(limits: StationLimits, tmp_path: Path) -> None:
    at_bound = simulated_run(run_id=2, process_intensity=BOUND_41_EVENTS)
    quiet = simulated_run(run_id=3, events=0, process_intensity=0.0)
    with WearLedger(tmp_path / "wear.sqlite") as ledger:
        for summary in (simulated_run(), at_bound, quiet):
            assert ledger.add_run(summary, T0_NS, limits.of(summary))
        assert ledger.tool(7).runs == 3
    # the simulated run is three orders of magnitude inside its bound
    assert BOUND_41_EVENTS / simulated_run().process_intensity > 1000


def test_the_tool_limit_is_the_program_s_else_the_sensor_range(limits: StationLimits) -> None:
    program = limits.of(simulated_run())
    assert (program.torque_limit_nm, program.max_time_s) == (T_LIM_NM, 6.0)
    unknown_program = limits.of(simulated_run(program_id=99))
    assert unknown_program.torque_limit_nm == pytest.approx(8388.608)  # the DBC's range
    assert unknown_program.max_time_s is None and "no program 99" in unknown_program.source
    other = limits.of(simulated_run(station="st9"))
    assert other.torque_limit_nm == pytest.approx(8388.608) and "no station file" in other.source
    # a station with no file is bounded loosely, but a forged 1e15 still is not within it
    assert refusal(simulated_run(station="st9", process_intensity=1e15), other) is not None


def real_runs() -> list[Path]:
    runs = sorted(PROJECT_REAL_RUNS.glob("Ch_*.json"))
    if HANDBOOK_REAL_RUNS.is_dir():
        runs += sorted(HANDBOOK_REAL_RUNS.glob("Ch_*.json"))
    return runs


def test_real_controller_runs_count_and_a_tampered_one_is_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Every real CS351 run is within its controller's own torque shutoff (MFs TorqueMax
    1.6 Nm); a copy whose torque was scaled ×100 (what a unit mix-up or a forged file
    would give) is refused, not counted, not written, named in one line."""
    tampered = tmp_path / "tampered.json"
    document = json.loads((PROJECT_REAL_RUNS / "Ch_000001596334.json").read_text())
    document["cycle"] = 7
    for step in document["tightening steps"]:
        graph = step["graph"]
        graph["torque values"] = [100 * value for value in graph["torque values"]]
    tampered.write_text(json.dumps(document))
    runs = real_runs()
    recordings = tmp_path / "recordings"
    argv = ["import", *map(str, [*runs, tampered]), "--recordings", str(recordings), "--no-rerun"]

    assert main(argv) == 2
    captured = capsys.readouterr()
    (line,) = [line for line in captured.err.splitlines() if "tampered.json" in line]
    assert "refused" in line and "beyond what" in line and "MFs TorqueMax" in line
    unique = {path.name for path in runs}  # the handbook holds the shipped four too
    again = len(runs) - len(unique)
    assert captured.out.splitlines()[-1].startswith(f"imported {len(unique)} of {len(runs) + 1}")
    assert captured.out.splitlines()[-1].endswith(f", {again} already there, 1 refused")
    assert not list(recordings.glob("cs351/*/cs351_run7_*"))
    with WearLedger(recordings / "wear.sqlite", read_only=True) as ledger:
        (tool,) = ledger.tools()
    assert tool.runs == len(unique)
