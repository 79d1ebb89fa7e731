"""A recording's samples as the offline trace CSV (``time_s,torque_nm,angle_deg,force_n``).

``time_s`` counts from the first exported sample of the run, on the clock
the predictor decided on: the sample's own clock (``Sample.time_s``: the
tool's Counter at its sample rate, or a controller's time for an import)
when the recording has it, else the acquisition's receive time
(``Sample.time_ns``, recordings made before the sample clock). So
``boltwatch predict`` on the export sees exactly what the live predictor saw.
A file may hold samples of more than one run (a recorder started mid-run);
the run exported is the one asked for, else the one with the most samples.
Damaged files export what is readable.
"""

from __future__ import annotations

import json
from collections import Counter
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from shared.recordings.mcap.recording_reader import RecordingScan
from shared.contract import channels
from shared.errors import InputError
from shared.contract import RunClock
from shared.contract import write_trace

SAMPLE_SCHEMA = channels.SAMPLES.schema_name


@dataclass(frozen=True, slots=True)
class ExportReport:
    target: Path
    run_id: int
    rows: int
    complete: bool
    state: str  # RecordingScan.describe() of the source


def default_target(source: Path) -> Path:
    return source.with_suffix(".csv")


def read_samples(scan: RecordingScan) -> list[dict[str, Any]]:
    """Every readable Sample of the recording as a dict, in file order."""
    samples = []
    for schema, _, message in scan.messages("/samples"):
        if schema is None or schema.name != SAMPLE_SCHEMA:
            continue  # raw channel: undecodable payloads
        samples.append(json.loads(message.data))
    return samples


def export_trace(
    source: Path, target: Path | None = None, run_id: int | None = None
) -> ExportReport:
    """Write the trace of one run of ``source`` to ``target`` (default: beside it, ``.csv``)."""
    source = Path(source)
    target = default_target(source) if target is None else Path(target)
    scan = RecordingScan(source)
    samples = read_samples(scan)
    runs = Counter(sample["run_id"] for sample in samples)
    if not runs:
        damage = "" if scan.damage is None else f" ({scan.damage})"
        raise InputError(f"{source}: no samples to export{damage}")
    if run_id is None:
        run_id = runs.most_common(1)[0][0]
    elif run_id not in runs:
        known = ", ".join(str(run) for run in sorted(runs))
        raise InputError(f"{source}: no samples of run {run_id} (runs in the file: {known})")
    chosen = [sample for sample in samples if sample["run_id"] == run_id]
    rows = write_trace(
        target,
        (
            (time_s, s["torque_nm"], s["angle_deg"], s["force_n"])
            for time_s, s in zip(run_times_s(chosen), chosen, strict=True)
        ),
    )
    return ExportReport(target, run_id, rows, scan.complete, scan.describe())


def run_times_s(samples: list[dict[str, Any]]) -> list[float]:
    """Each sample's time since the first, on its own clock when every sample has one."""
    if all(sample.get("time_s") is not None for sample in samples):
        t0_s = samples[0]["time_s"]
        return [sample["time_s"] - t0_s for sample in samples]
    clock = RunClock(samples[0]["time_ns"])
    return clock.seconds_of(sample["time_ns"] for sample in samples)
