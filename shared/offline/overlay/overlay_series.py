"""What the overlay plots, as data: each run's aligned series and the programs' windows.

The x axes are those of one run, the *frame*: the reference run (``--reference``),
else the first run that reaches the alignment point. Every other run is
shifted, in angle and in time, so that its alignment point falls on the
frame's: ``x = x_run - x_run[i_run] + x_frame[i_frame]``. So the frame's own
values are never moved, and the windows (which a run's final angle is judged
against, in that run's angle) are drawn where they belong: each program's
windows in the frame of the run they are taken from, shifted as that run is.

A run that never reaches the alignment point is left unaligned (not shifted,
its ``note`` says why); if the frame would have to be such a run, the overlay
is refused (:class:`~shared.errors.InputError`).
"""

from __future__ import annotations

from dataclasses import dataclass

from shared.contract import TighteningResult
from shared.errors import InputError
from shared.offline.overlay.overlay_alignment import Alignment, align_index
from shared.offline.overlay.overlay_run import FloatArray, OverlayRun


@dataclass(frozen=True, slots=True)
class RunSeries:
    """One run as drawn: x in the frame (aligned unless ``aligned`` is False)."""

    run_id: int
    label: str
    reference: bool
    verdict: str  # "OK", "NOK" or "no result"
    nok_reasons: str
    program_id: int | None
    aligned: bool
    note: str  # why it is not aligned ("" when it is)
    angle_deg: FloatArray
    time_s: FloatArray
    torque_nm: FloatArray
    force_n: FloatArray | None
    shift_angle_deg: float
    shift_time_s: float
    spindle: int | None = None  # a multi-spindle station's run: its spindle


@dataclass(frozen=True, slots=True)
class ProgramWindows:
    """A program's windows from a run's result, angles shifted into the frame (None: open)."""

    program_id: int
    program_name: str
    from_run: int
    torque_min_nm: float | None
    torque_max_nm: float | None
    angle_min_deg: float | None
    angle_max_deg: float | None
    force_min_n: float | None
    force_max_n: float | None


@dataclass(frozen=True, slots=True)
class Overlay:
    alignment: Alignment
    frame_run: int
    series: tuple[RunSeries, ...]  # the reference first, then the runs in the order given
    windows: tuple[ProgramWindows, ...]

    @property
    def unaligned(self) -> tuple[RunSeries, ...]:
        return tuple(series for series in self.series if not series.aligned)


def build_overlay(
    runs: list[OverlayRun], reference: OverlayRun | None, alignment: Alignment
) -> Overlay:
    """The overlay of ``runs`` (and ``reference``, drawn once) aligned at ``alignment``."""
    ordered = ([reference] if reference is not None else []) + [
        run for run in runs if reference is None or run.run_id != reference.run_id
    ]
    ordered = list({run.run_id: run for run in reversed(ordered)}.values())[::-1]  # once each
    indexes = {run.run_id: align_index(run, alignment) for run in ordered}
    frame = _frame(ordered, reference, indexes, alignment)
    frame_index = indexes[frame.run_id]
    assert frame_index is not None
    series = tuple(
        _series(run, run is reference, indexes[run.run_id], frame, frame_index, alignment)
        for run in ordered
    )
    return Overlay(alignment, frame.run_id, series, _windows(ordered, series))


def _frame(
    ordered: list[OverlayRun],
    reference: OverlayRun | None,
    indexes: dict[int, int | None],
    alignment: Alignment,
) -> OverlayRun:
    if reference is not None:
        if indexes[reference.run_id] is None:
            raise InputError(
                f"reference run {reference.run_id} {alignment.missing()}: no point to align "
                f"the runs on ({alignment.describe()}); choose another --align or --reference"
            )
        return reference
    for run in ordered:
        if indexes[run.run_id] is not None:
            return run
    names = ", ".join(str(run.run_id) for run in ordered)
    raise InputError(
        f"none of the runs ({names}) reaches the alignment point ({alignment.describe()}): "
        "nothing to align on; choose another --align"
    )


def _series(
    run: OverlayRun,
    is_reference: bool,
    index: int | None,
    frame: OverlayRun,
    frame_index: int,
    alignment: Alignment,
) -> RunSeries:
    if index is None:
        shift_angle, shift_time, note = 0.0, 0.0, f"not aligned: {alignment.missing()}"
    else:
        shift_angle = float(frame.angle_deg[frame_index] - run.angle_deg[index])
        shift_time = float(frame.time_s[frame_index] - run.time_s[index])
        note = ""
    result = run.result
    return RunSeries(
        run.run_id,
        run.label,
        is_reference,
        run.verdict,
        result.nok_reasons if result is not None else "",
        result.program_id if result is not None else None,
        index is not None,
        note,
        run.angle_deg + shift_angle,
        run.time_s + shift_time,
        run.torque_nm,
        run.force_n,
        shift_angle,
        shift_time,
        result.spindle if result is not None else None,
    )


def _windows(runs: list[OverlayRun], series: tuple[RunSeries, ...]) -> tuple[ProgramWindows, ...]:
    """One set of windows per program (the first run's of it: the reference's if it ran it)."""
    shifts = {drawn.run_id: drawn.shift_angle_deg for drawn in series}
    found: dict[int, ProgramWindows] = {}
    for run in runs:
        result = run.result
        if result is None or result.program_id in found or not _has_window(result):
            continue
        shift = shifts[run.run_id]
        angle = result.final_angle_deg
        found[result.program_id] = ProgramWindows(
            result.program_id,
            result.program_name,
            run.run_id,
            result.final_torque_nm.min,
            result.final_torque_nm.max,
            None if angle.min is None else angle.min + shift,
            None if angle.max is None else angle.max + shift,
            result.final_force_n.min,
            result.final_force_n.max,
        )
    return tuple(found.values())


def _has_window(result: TighteningResult) -> bool:
    figures = (result.final_torque_nm, result.final_angle_deg, result.final_force_n)
    return any(figure.min is not None or figure.max is not None for figure in figures)
