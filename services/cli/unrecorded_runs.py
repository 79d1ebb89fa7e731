"""The runs ``boltwatch up`` saw that have no run file: "done" for ``up`` is done and recorded.

A run file takes its name only once it is complete (the recorder writes it
under a writing name and renames it), so a run with no file under a run
file's name, written since ``up`` started, was not recorded: the disk was
full or below its reserve, or failed; or the recorder died. ``up`` names them
in one line with the recorder's log and ends with a non-zero exit status. A
multi-spindle station's cycle is one file, named by the cycle's first run to
start: a spindle's run is recorded when a file of any run of its cycle is.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

from shared.contract import RunSummary
from shared.recordings import run_files


def unrecorded_runs(
    folder: Path, summaries: Sequence[RunSummary], since_s: float
) -> list[RunSummary]:
    """The runs of ``summaries`` with no run file under ``folder`` written since ``since_s``
    (seconds since the epoch)."""
    cycles: dict[tuple[str, int], list[int]] = {}
    for summary in summaries:
        if summary.sync_id is not None:
            cycles.setdefault((summary.station, summary.sync_id), []).append(summary.run_id)
    return [
        summary
        for summary in summaries
        if not any(
            _written_since(path, since_s)
            for run_id in _named_by(summary, cycles)
            for path in run_files(folder, summary.station, run_id)
        )
    ]


def _named_by(summary: RunSummary, cycles: dict[tuple[str, int], list[int]]) -> list[int]:
    """The runs whose file may hold ``summary``'s run: its own, or its cycle's runs."""
    if summary.sync_id is None:
        return [summary.run_id]
    return cycles[(summary.station, summary.sync_id)]


def unrecorded_note(unrecorded: Sequence[RunSummary], total: int, recorder_log: Path) -> str:
    """One line: how many runs, which, and where to read why."""
    by_station: dict[str, list[int]] = {}
    for summary in unrecorded:
        by_station.setdefault(summary.station, []).append(summary.run_id)
    which = "; ".join(
        f"{station} run{'s' * (len(ids) > 1)} {', '.join(str(i) for i in ids)}"
        for station, ids in by_station.items()
    )
    return (
        f"NOT RECORDED: {len(unrecorded)} of {total} runs have no recording ({which}); "
        f"why: {recorder_log}"
    )


def _written_since(path: Path, since_s: float) -> bool:
    try:
        return path.stat().st_mtime >= since_s
    except OSError:
        return False
