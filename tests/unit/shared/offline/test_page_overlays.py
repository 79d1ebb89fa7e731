"""Runs side by side for the line's page: a part's runs of several stations (whose run ids
meet) overlaid, and a program's band (lowest, highest, median of its runs) in the frame of
the run drawn against it, with the figures worked out by hand."""

from __future__ import annotations

import json

import numpy as np
import pytest

from shared.contract import JudgedFigure
from shared.errors import InputError
from shared.offline.overlay import (
    OverlayRun,
    parse_alignment,
    part_overlay_document,
    program_band_document,
)
from tests.support import factories


def _run(
    run_id: int, slope: float, end_deg: float, start_deg: float = 0.0, verdict: str = "OK"
) -> OverlayRun:
    """A run whose torque is ``slope`` × its angle (rising from ``start_deg`` to ``end_deg``
    in 0.1 degrees a millisecond) and whose preload is 1000 × its torque."""
    angle = np.arange(start_deg, end_deg + 1e-9, 0.1)
    time_s = np.arange(len(angle)) / 1000.0
    torque = slope * angle
    result = factories.result(
        run_id,
        result=verdict,
        final_angle_deg=JudgedFigure(end_deg, 5.0, 9.0, "ok"),
        final_torque_nm=JudgedFigure(slope * end_deg, 10.0, 40.0, "ok"),
    )
    return OverlayRun(
        str(run_id), (), run_id, time_s, (time_s * 1e9).astype(np.int64), torque, angle,
        torque * 1000.0, (), result, "",
    )  # fmt: skip


def test_a_program_s_band_is_lowest_highest_and_median_of_the_runs_that_reach_each_angle() -> None:
    shown = ("st1/5", _run(5, 2.0, 10.0))
    others = [("st1/1", _run(1, 1.0, 10.0)), ("st1/2", _run(2, 3.0, 10.0))]
    others.append(("st1/3", _run(3, 4.0, 5.0)))  # stopped early: reaches 5 degrees only
    band = program_band_document(shown, others, parse_alignment("start"), grid_points=11)
    json.dumps(band, allow_nan=False)
    assert band["frame"] == "st1/5" and band["runs"] == ["st1/1", "st1/2", "st1/3"]
    over = band["over_angle"]
    assert over["x"] == pytest.approx([float(x) for x in range(11)])
    torque = over["torque_nm"]
    # up to 5 degrees runs 1, 2, 3 (slopes 1, 3, 4), beyond it runs 1 and 2 (slopes 1, 3)
    assert torque["low"] == pytest.approx([1.0 * x for x in range(11)])
    assert torque["high"] == pytest.approx(
        [4.0 * x for x in range(6)] + [3.0 * x for x in range(6, 11)]
    )
    assert torque["median"] == pytest.approx(
        [3.0 * x for x in range(6)] + [2.0 * x for x in range(6, 11)]
    )
    assert over["force_n"]["low"] == pytest.approx([1000.0 * x for x in range(11)])
    assert band["over_time"]["torque_nm"]["high"][0] == pytest.approx(0.0)


def test_the_band_is_drawn_in_the_frame_of_the_run_against_it() -> None:
    # aligned at 5 Nm: the shown run (1 Nm a degree) gets there at 5 degrees, runs 1 and 3
    # (2.5 Nm a degree) at 2 degrees: they move by +3 degrees; run 2 never gets there
    shown = ("st1/9", _run(9, 1.0, 12.0))
    others = [("st1/1", _run(1, 2.5, 10.0)), ("st1/2", _run(2, 1.0, 4.0))]
    others.append(("st1/3", _run(3, 2.5, 6.0)))
    band = program_band_document(shown, others, parse_alignment("torque:5"), grid_points=11)
    assert band["runs"] == ["st1/1", "st1/3"]
    assert band["left_out"] == [{"key": "st1/2", "note": "not aligned: never reaches 5 Nm"}]
    over = band["over_angle"]
    assert over["x"] == pytest.approx([3.0 + x for x in range(11)])  # 0..10 degrees, moved
    torque = over["torque_nm"]
    # both runs up to 9 degrees of the frame (6 of their own), run 1 alone beyond: no band
    assert torque["low"][:7] == pytest.approx([2.5 * x for x in range(7)])
    assert torque["low"][7:] == [None] * 4
    lonely = program_band_document(shown, others[:2], parse_alignment("torque:5"))
    assert lonely["over_angle"] is None  # one run is no band


def test_a_part_s_runs_of_two_stations_with_the_same_run_id_are_both_drawn() -> None:
    first = ("st1/7", _run(7, 2.0, 8.0))
    second = ("st2/7", _run(7, 3.0, 6.0, verdict="NOK"))
    document = part_overlay_document([first, second], "st2/7", parse_alignment("start"))
    json.dumps(document, allow_nan=False)
    assert document["frame"] == "st2/7"
    assert [(r["key"], r["reference"], r["verdict"]) for r in document["runs"]] == [
        ("st1/7", False, "OK"),
        ("st2/7", True, "NOK"),
    ]
    assert document["runs"][1]["samples"] == len(document["runs"][1]["torque_nm"]) == 61
    (windows,) = document["windows"]  # one program: from the first of its runs
    assert windows["from"] == "st1/7" and windows["torque_nm"] == [10.0, 40.0]
    with pytest.raises(InputError, match="none of the runs reaches"):
        part_overlay_document([first, second], "st2/7", parse_alignment("torque:500"))
