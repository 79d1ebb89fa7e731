"""Runs side by side as plain data for a browser to draw (the line's page), ready for JSON.

The runs of a part may come from several stations, whose run ids meet; so here a run is
named by a key of the caller's (``"st1/1042"``), not by its id as in
:func:`~.overlay_series.build_overlay`. They are aligned the same way: the frame is the
reference run (the one the page shows) when it reaches the alignment point, else the
first that does; each other run is shifted, in angle and in time, so that its point
falls on the frame's (:func:`aligned`); a run that never reaches it stays where it is,
with a note. :func:`part_overlay_document` gives each run's curve (thinned as
:func:`~shared.offline.post_mortem.curve_points.drawn_indices` thins one run) with its
verdict, and each program's windows from the first of its runs with a result (angles
shifted with that run).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from shared.errors import InputError
from shared.offline.overlay.overlay_alignment import Alignment, align_index
from shared.offline.overlay.overlay_run import FloatArray, OverlayRun
from shared.offline.post_mortem.curve_points import TIME_DECIMALS, drawn_indices, json_column

#: the points of each run of an overlay sent at most (a part's runs, a program's band input)
OVERLAY_POINTS = 4000


@dataclass(frozen=True, slots=True)
class AlignedRun:
    """One run in the frame: its x shifted (0 when not aligned, ``note`` says why)."""

    key: str
    run: OverlayRun
    aligned: bool
    note: str
    shift_angle_deg: float
    shift_time_s: float

    @property
    def angle_deg(self) -> FloatArray:
        return self.run.angle_deg + self.shift_angle_deg

    @property
    def time_s(self) -> FloatArray:
        return self.run.time_s + self.shift_time_s


def aligned(
    runs: Sequence[tuple[str, OverlayRun]], reference: str, alignment: Alignment
) -> tuple[str, list[AlignedRun]]:
    """The frame's key and every run of ``runs`` (key, run) in it; InputError when no run
    reaches the alignment point."""
    indexes = {key: align_index(run, alignment) for key, run in runs}
    order = [key for key, _ in runs if key == reference] + [key for key, _ in runs]
    frame_key = next((key for key in order if indexes[key] is not None), None)
    if frame_key is None:
        raise InputError(
            f"none of the runs reaches the alignment point ({alignment.describe()}): "
            "nothing to align on"
        )
    frame = dict(runs)[frame_key]
    frame_index = indexes[frame_key]
    assert frame_index is not None
    placed = []
    for key, run in runs:
        index = indexes[key]
        if index is None:
            placed.append(AlignedRun(key, run, False, f"not aligned: {alignment.missing()}", 0, 0))
            continue
        shift_angle = float(frame.angle_deg[frame_index] - run.angle_deg[index])
        shift_time = float(frame.time_s[frame_index] - run.time_s[index])
        placed.append(AlignedRun(key, run, True, "", shift_angle, shift_time))
    return frame_key, placed


def part_overlay_document(
    runs: Sequence[tuple[str, OverlayRun]],
    reference: str,
    alignment: Alignment,
    max_points: int = OVERLAY_POINTS,
) -> dict[str, Any]:
    """The runs of ``runs`` (key, run) overlaid in the frame of ``reference`` (see the
    module docstring)."""
    frame_key, placed = aligned(runs, reference, alignment)
    return {
        "alignment": alignment.describe(),
        "frame": frame_key,
        "runs": [_series(run, run.key == reference, max_points) for run in placed],
        "windows": _windows(placed),
    }


def _series(placed: AlignedRun, reference: bool, max_points: int) -> dict[str, Any]:
    run = placed.run
    kept = drawn_indices(run.torque_nm, max_points)
    result = run.result
    return {
        "key": placed.key,
        "run_id": run.run_id,
        "station": None if result is None else result.station,
        "reference": reference,
        "verdict": run.verdict,
        "nok_reasons": "" if result is None else result.nok_reasons,
        "program_id": None if result is None else result.program_id,
        "aligned": placed.aligned,
        "note": placed.note,
        "damage": run.damage,
        "samples": len(run.time_s),
        "time_s": json_column(placed.time_s[kept], TIME_DECIMALS),
        "angle_deg": json_column(placed.angle_deg[kept]),
        "torque_nm": json_column(run.torque_nm[kept]),
        "force_n": None if run.force_n is None else json_column(run.force_n[kept]),
    }


def _windows(placed: Sequence[AlignedRun]) -> list[dict[str, Any]]:
    """One set of windows per program: the first of its runs with a result that has one,
    its angles shifted as that run is."""
    found: dict[int, dict[str, Any]] = {}
    for run in placed:
        result = run.run.result
        if result is None or result.program_id in found:
            continue
        figures = (result.final_torque_nm, result.final_angle_deg, result.final_force_n)
        if all(figure.min is None and figure.max is None for figure in figures):
            continue
        angle = result.final_angle_deg
        shift = run.shift_angle_deg
        found[result.program_id] = {
            "program_id": result.program_id,
            "program_name": result.program_name,
            "from": run.key,
            "torque_nm": [result.final_torque_nm.min, result.final_torque_nm.max],
            "angle_deg": [
                None if angle.min is None else angle.min + shift,
                None if angle.max is None else angle.max + shift,
            ],
            "force_n": [result.final_force_n.min, result.final_force_n.max],
        }
    return list(found.values())
