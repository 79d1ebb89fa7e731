"""A tightening as the results store keeps it: a :class:`TighteningResult`, where it was
tightened (plant, line, the station's name), where its recording is, and when it was stored.

:func:`stored_result` makes one from a result (and its run's summary: the
events of a run whose result has none, as ``report`` counts them);
:meth:`StoredResult.result` gives the TighteningResult back, equal to the
one stored, so what reads the store (``report``) computes what it computed
from the files; its part id as the part search asks for one
(:func:`stored_part_id`: no spaces at either end, "" none). :func:`to_row` /
:func:`from_row` are its rows, in the order of
:data:`~shared.results.results_schema.TIGHTENING_COLUMNS`; a multi-spindle cycle's
common result is :func:`cycle_rows` (one per spindle's run) and, read back for a
run, :class:`RunCycle`.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace
from typing import Any

from shared.contract import (
    CycleResult,
    CycleSpindle,
    JudgedFigure,
    ResultStep,
    RunSummary,
    TighteningResult,
    Verdict,
)


@dataclass(frozen=True, slots=True)
class RunCycle:
    """The multi-spindle cycle a tightening is a spindle's run of: its common result."""

    sync_id: int
    spindles: int  # the spindles of the cycle
    result: Verdict  # OK only when every spindle is
    nok_reasons: str  # why the cycle is NOK ("" when OK)
    ended_ns: int  # when its last spindle's run ended


@dataclass(frozen=True, slots=True)
class StoredResult:
    """One row of ``tightenings`` (the result's steps: its ``tightening_steps``; a
    multi-spindle cycle's run: its cycle's common result, of ``cycle_results``)."""

    result: TighteningResult
    line: str = ""  # the station's line ("": none named)
    recording: str | None = None  # the MCAP file's path on recording_host; None: unknown
    recording_host: str | None = None
    stored_ns: int = 0
    plant: str = ""  # the plant of the station's line ("": none named)
    # the station's name for people when the result was stored ("": none, its id is shown)
    station_name: str = ""
    # a spindle's run of a multi-spindle cycle whose common result is stored: that cycle
    # (None: a single-spindle station's, or the cycle's result not stored)
    cycle: RunCycle | None = None


def stored_result(
    result: TighteningResult,
    line: str,
    recording: str | None,
    recording_host: str | None,
    stored_ns: int,
    summary: RunSummary | None = None,
    *,
    plant: str = "",
    station_name: str = "",
) -> StoredResult:
    """``result`` to store; ``summary``: its run's, whose events count when it has none."""
    if result.events is None and summary is not None and summary.run_id == result.run_id:
        result = replace(result, events=summary.events)
    return StoredResult(result, line, recording, recording_host, stored_ns, plant, station_name)


def stored_part_id(part_id: str | None) -> str | None:
    """A result's part id as the store keeps it: without spaces at either end (a scanner's
    padding, as every writer of ours trims it and the part search asks), "" none (None)."""
    return (part_id or "").strip() or None


def to_row(stored: StoredResult) -> tuple[Any, ...]:
    r = stored.result
    torque, angle, force = r.final_torque_nm, r.final_angle_deg, r.final_force_n
    return (
        r.station, r.run_id, stored.plant, stored.line, stored.station_name, r.tightening_id,
        r.tool_id, r.program_id, r.program_name, stored_part_id(r.part_id), r.batch_counter,
        r.time_ns,
        r.result, r.nok_reasons,
        torque.value, torque.min, torque.max, torque.status,
        angle.value, angle.min, angle.max, angle.status,
        force.value, force.min, force.max, force.status,
        r.stop_reason, r.events, r.process_intensity, r.source,
        stored.recording, stored.recording_host, stored.stored_ns, r.part_source, r.pulses,
        r.spindle, r.sync_id,
    )  # fmt: skip


def step_rows(stored: StoredResult) -> list[tuple[Any, ...]]:
    r = stored.result
    return [
        (r.station, r.run_id, index, step.name, step.function, step.nominal, step.actual,
         step.status)
        for index, step in enumerate(r.steps)
    ]  # fmt: skip


def from_row(row: Sequence[Any], steps: Sequence[ResultStep] = ()) -> StoredResult:
    (
        station, run_id, plant, line, station_name, tightening_id, tool_id, program_id,
        program_name, part_id, batch_counter, ended_ns, verdict, nok_reasons,
        torque, torque_min, torque_max, torque_status,
        angle, angle_min, angle_max, angle_status,
        force, force_min, force_max, force_status,
        stop_reason, events, intensity, source, recording, recording_host, stored_ns,
        part_source, pulses, spindle, sync_id,
    ) = row  # fmt: skip
    result = TighteningResult(
        station=station,
        tightening_id=int(tightening_id),
        run_id=int(run_id),
        tool_id=int(tool_id),
        program_id=int(program_id),
        program_name=program_name,
        time_ns=int(ended_ns),
        part_id=part_id,
        batch_counter=None if batch_counter is None else int(batch_counter),
        final_torque_nm=JudgedFigure(torque, torque_min, torque_max, torque_status),
        final_angle_deg=JudgedFigure(angle, angle_min, angle_max, angle_status),
        final_force_n=JudgedFigure(force, force_min, force_max, force_status),
        result=verdict,
        nok_reasons=nok_reasons,
        stop_reason=stop_reason,
        events=None if events is None else int(events),
        process_intensity=intensity,
        source=source,
        steps=list(steps),
        part_source=part_source,
        pulses=None if pulses is None else int(pulses),
        spindle=None if spindle is None else int(spindle),
        sync_id=None if sync_id is None else int(sync_id),
    )
    return StoredResult(
        result, line, recording, recording_host, int(stored_ns), plant, station_name
    )


def cycle_rows(cycle: CycleResult, stored_ns: int) -> list[tuple[Any, ...]]:
    """The ``cycle_results`` rows of a cycle's common result: one per spindle's run of it (a
    spindle whose result never came has no run, and no row: the others' say it)."""
    return [
        (cycle.station, spindle.run_id, cycle.sync_id, spindle.spindle, len(cycle.spindles),
         cycle.result, cycle.nok_reasons, cycle.time_ns, stored_part_id(cycle.part_id),
         cycle.program_id, cycle.source, stored_ns)
        for spindle in cycle.spindles
        if spindle.run_id is not None
    ]  # fmt: skip


def stored_cycle(
    station: str, sync_id: int, rows: Sequence[Sequence[Any]], verdicts: dict[int, str]
) -> CycleResult:
    """The CycleResult of one cycle's ``cycle_results`` rows (run_id, spindle, spindles,
    result, nok_reasons, ended_ns, part_id, program_id, source), as :func:`cycle_rows` made
    them; ``verdicts``: each stored run's result (a spindle's run not stored: its verdict
    None unless the cycle is OK, which every spindle then is)."""
    first = rows[0]
    runs = {int(row[1]): int(row[0]) for row in rows}
    spindles = []
    for spindle in range(1, max(int(first[2]), *runs) + 1):
        run_id = runs.get(spindle)
        stored = None if run_id is None else verdicts.get(run_id)
        verdict: Verdict | None = "OK" if stored == "OK" else "NOK" if stored == "NOK" else None
        if run_id is not None and verdict is None and first[3] == "OK":
            verdict = "OK"
        spindles.append(CycleSpindle(spindle, run_id, verdict))
    return CycleResult(
        station=station,
        sync_id=sync_id,
        time_ns=int(first[5]),
        part_id=first[6],
        program_id=int(first[7]),
        result=first[3],
        nok_reasons=first[4],
        source=first[8],
        spindles=spindles,
    )


def cycle_of(row: Sequence[Any]) -> RunCycle:
    """A ``cycle_results`` row's sync id, spindles, result, NOK reasons and end as a RunCycle."""
    sync_id, spindles, result, nok_reasons, ended_ns = row
    return RunCycle(int(sync_id), int(spindles), result, nok_reasons, int(ended_ns))


def step_of(row: Sequence[Any]) -> ResultStep:
    """A ``tightening_steps`` row (without its key columns) as a ResultStep."""
    name, function, nominal, actual, status = row
    return ResultStep(name, function, nominal, actual, status)
