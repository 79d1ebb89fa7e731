"""A multi-spindle cycle's runs side by side for the page, read from the cycle's one file.

A multi-spindle station's cycle is one recording holding every spindle's run of it
(:mod:`shared.offline.overlay`'s :func:`~shared.offline.overlay.read_overlay_cycle` reads
them, in spindle order, as ``inspect --overlay --cycle`` does). :func:`cycle_document` is
what ``/api/runs/ST/RUN/cycle`` answers: the runs overlaid as a part's are
(:func:`~shared.offline.overlay.part_overlay_document`, the run asked for the reference),
each with its spindle, and the cycle's common result as the results store holds it (None:
not stored yet). :func:`with_spindles` puts each run's spindle into an overlay's runs (a
single-spindle station's runs get none). Pure: files in, data out.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

from shared.offline.overlay import (
    Alignment,
    OverlayRun,
    part_overlay_document,
    read_overlay_cycle,
)
from shared.results import StoredResult


def with_spindles(document: dict[str, Any], runs: Sequence[OverlayRun]) -> dict[str, Any]:
    """``document``'s runs, each of a multi-spindle station with its ``spindle``."""
    spindles = {
        run.run_id: run.result.spindle
        for run in runs
        if run.result is not None and run.result.spindle is not None
    }
    for series in document["runs"]:
        spindle = spindles.get(series["run_id"])
        if spindle is not None:
            series["spindle"] = spindle
    return document


def cycle_document(
    station: str,
    run_id: int,
    files: Sequence[Path],
    stored: StoredResult | None,
    alignment: Alignment,
) -> dict[str, Any]:
    """Every spindle's run of the cycle of ``run_id`` (of ``station``, in ``files``) overlaid
    (InputError: none reaches the alignment point, the files cannot be read)."""
    key = f"{station}/{run_id}"
    runs = read_overlay_cycle(key, list(files), run_id)
    keyed = [(f"{station}/{run.run_id}", run) for run in runs]
    document = with_spindles(part_overlay_document(keyed, key, alignment), runs)
    drawn = {
        run.result.spindle
        for run in runs
        if run.result is not None and run.result.spindle is not None
    }
    cycle = None if stored is None else stored.cycle
    spindles = max(drawn | {cycle.spindles if cycle is not None else 0}, default=0)
    names = ", ".join(path.name for path in files)
    left_out = [
        f"spindle {spindle}: no run of it in {names}"
        for spindle in range(1, spindles + 1)
        if spindle not in drawn
    ]
    common = None
    if cycle is not None:
        assert stored is not None
        common = {
            "sync_id": cycle.sync_id,
            "spindles": cycle.spindles,
            "result": cycle.result,
            "nok_reasons": cycle.nok_reasons,
            "part_id": stored.result.part_id,
        }
    return document | {"cycle": common, "left_out": left_out}
