"""One recorded run for the overlay: its samples as arrays, its events and its result.

A run is named on the command line by its id (looked up in a station's
recordings folder, ``<folder>/<station>/<date>/<station>_run<id>_*.mcap``;
a run the recorder split into parts is read from all of them) or by the path
of an MCAP file (the run with the most samples in it). Damaged files are read
as far as they go (:mod:`~shared.recordings.mcap.recording_reader`); a file
of several that cannot be read at all (empty, not MCAP, not a regular file)
is skipped; ``damage`` says what was lost, naming each file. A run read already for its
post-mortem (:func:`~shared.offline.post_mortem.read_run_files`) is one too
(:func:`overlay_run_of`: the line's page reads each run once for both).

A multi-spindle station's cycle is one file holding every spindle's run of it:
:func:`read_overlay_cycle` reads each of them, in spindle order.

Run time is the sample's own clock (``Sample.time_s``, the tool's counter)
when every sample has it, else the receive time (``time_ns``), counted from
the run's first sample in both cases.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import numpy.typing as npt
from mcap.records import Message

from shared.contract import Sample, StickSlipEvent, TighteningResult, channels, decode
from shared.errors import InputError
from shared.offline.post_mortem.post_mortem_run import RecordedRun
from shared.recordings import run_file_prefix, run_files, station_folder_name
from shared.recordings.mcap import RecordingScan

_SCHEMAS = {
    channels.SAMPLES.schema_name: Sample,
    channels.EVENTS.schema_name: StickSlipEvent,
    channels.RESULTS.schema_name: TighteningResult,
}

FloatArray = npt.NDArray[np.float64]


@dataclass(frozen=True, slots=True)
class OverlayRun:
    """One run's traces (arrays of equal length, in sample order) and what the file says."""

    label: str  # how the command line named it (a run id or a path)
    files: tuple[Path, ...]
    run_id: int
    time_s: FloatArray  # since the run's first sample
    time_ns: npt.NDArray[np.int64]  # receive times, to find an event's sample
    torque_nm: FloatArray
    angle_deg: FloatArray
    force_n: FloatArray | None  # None: no preload measured in this run (NaN: a lost sample)
    events: tuple[StickSlipEvent, ...]
    result: TighteningResult | None  # None: the recording has no result of this run
    damage: str  # "" when every file was whole

    @property
    def verdict(self) -> str:
        return self.result.result if self.result is not None else "no result"


def find_run_files(
    folder: Path, station: str, run_id: int, loops: list[Path] | None = None
) -> list[Path]:
    """The MCAP files of run ``run_id`` of ``station`` under the recordings ``folder`` (symlink
    loops met on the way: skipped, in ``loops``; ``folder`` one: InputError)."""
    files = run_files(folder, station, run_id, loops)
    if not files:
        station_folder = folder / station_folder_name(station)
        raise InputError(
            f"run {run_id}: not found, no {run_file_prefix(station, run_id)}*.mcap in the day "
            f"folders of {station_folder} (station {station}'s recordings)"
        )
    return files


@dataclass(frozen=True, slots=True)
class _Read:
    """What files hold: their samples, events, results, and what was lost."""

    samples: list[Sample]
    events: list[StickSlipEvent]
    results: list[TighteningResult]
    damage: list[str]


def _read_files(files: list[Path]) -> _Read:
    read = _Read([], [], [], [])
    for path in files:
        try:
            _read_file(path, read.samples, read.events, read.results, read.damage)
        except InputError as err:
            if len(files) == 1:
                raise
            read.damage.append(f"{err}; skipped")
    return read


def read_overlay_run(label: str, files: list[Path], run_id: int | None = None) -> OverlayRun:
    """Run ``run_id`` of ``files`` (None: the run with the most samples in them)."""
    read = _read_files(files)
    run_id = _chosen_run(label, files, read.samples, run_id, read.damage)
    return _overlay_run(label, files, run_id, read)


def read_overlay_cycle(
    label: str, files: list[Path], run_id: int | None = None
) -> list[OverlayRun]:
    """Every run of the multi-spindle cycle in ``files`` (the cycle of ``run_id``; None: of the
    run with the most samples), in spindle order; a run of a single-spindle station alone."""
    read = _read_files(files)
    run_id = _chosen_run(label, files, read.samples, run_id, read.damage)
    results = {result.run_id: result for result in read.results}
    chosen = results.get(run_id)
    sync_id = chosen.sync_id if chosen is not None else None
    if sync_id is None:
        return [_overlay_run(label, files, run_id, read)]
    cycle = sorted(
        (result.spindle or 0, result.run_id)
        for result in results.values()
        if result.sync_id == sync_id and result.station == chosen.station  # type: ignore[union-attr]
    )
    sampled = {sample.run_id for sample in read.samples}
    return [
        _overlay_run(f"{label} spindle {spindle}", files, member, read)
        for spindle, member in cycle
        if member in sampled
    ]


def _overlay_run(label: str, files: list[Path], run_id: int, read: _Read) -> OverlayRun:
    samples, events, results, damage = read.samples, read.events, read.results, read.damage
    own = [sample for sample in samples if sample.run_id == run_id]
    own.sort(key=lambda sample: sample.sequence)
    result = next((r for r in reversed(results) if r.run_id == run_id), None)
    return OverlayRun(
        label,
        tuple(files),
        run_id,
        _run_time_s(own),
        np.array([sample.time_ns for sample in own], dtype=np.int64),
        np.array([sample.torque_nm for sample in own], dtype=np.float64),
        np.array([sample.angle_deg for sample in own], dtype=np.float64),
        _force_n(own),
        tuple(sorted((e for e in events if e.run_id == run_id), key=lambda e: e.index)),
        result,
        "; ".join(damage),
    )


def overlay_run_of(run: RecordedRun, label: str) -> OverlayRun:
    """``run`` (read for its post-mortem) as one run of an overlay, named ``label``."""
    own = sorted(run.samples, key=lambda sample: sample.sequence)
    return OverlayRun(
        label,
        tuple(run.sources or [run.source]),
        run.run_id,
        _run_time_s(own),
        np.array([sample.time_ns for sample in own], dtype=np.int64),
        np.array([sample.torque_nm for sample in own], dtype=np.float64),
        np.array([sample.angle_deg for sample in own], dtype=np.float64),
        _force_n(own),
        tuple(sorted(run.events, key=lambda e: e.index)),
        run.result,
        "" if run.complete else run.state,
    )


def _read_file(
    path: Path,
    samples: list[Sample],
    events: list[StickSlipEvent],
    results: list[TighteningResult],
    damage: list[str],
) -> None:
    """The samples, events and results of one file (as far as it reads); InputError: none."""
    scan = RecordingScan(path)
    for record in scan.records():
        if not isinstance(record, Message):
            continue
        channel = scan.channels.get(record.channel_id)
        schema = scan.schemas.get(channel.schema_id) if channel is not None else None
        message_type = _SCHEMAS.get(schema.name) if schema is not None else None
        if message_type is None:
            continue
        try:
            message: Sample | StickSlipEvent | TighteningResult = decode(message_type, record.data)
        except InputError:
            continue  # what cannot be decoded is not drawn
        if isinstance(message, Sample):
            samples.append(message)
        elif isinstance(message, StickSlipEvent):
            events.append(message)
        else:
            results.append(message)
    if not scan.complete:
        damage.append(scan.describe())


def _chosen_run(
    label: str, files: list[Path], samples: list[Sample], run_id: int | None, damage: list[str]
) -> int:
    counts: dict[int, int] = {}
    for sample in samples:
        counts[sample.run_id] = counts.get(sample.run_id, 0) + 1
    where = ", ".join(str(path) for path in files)
    lost = f" ({'; '.join(damage)})" if damage else ""
    if run_id is None:
        if not counts:
            raise InputError(f"{label}: no samples in {where}{lost}: nothing to draw")
        return max(counts, key=counts.__getitem__)
    if run_id not in counts:
        others = f" (runs with samples there: {', '.join(map(str, sorted(counts)))})"
        raise InputError(
            f"run {run_id}: no samples in {where}{others if counts else ''}{lost}: nothing to draw"
        )
    return run_id


def _run_time_s(samples: list[Sample]) -> FloatArray:
    if samples and all(sample.time_s is not None for sample in samples):
        clock = np.array([sample.time_s for sample in samples], dtype=np.float64)
        return clock - clock[0]
    times_ns = np.array([sample.time_ns for sample in samples], dtype=np.int64)
    return (times_ns - times_ns[0]).astype(np.float64) / 1e9


def _force_n(samples: list[Sample]) -> FloatArray | None:
    if all(sample.force_n is None for sample in samples):
        return None
    return np.array(
        [np.nan if sample.force_n is None else sample.force_n for sample in samples],
        dtype=np.float64,
    )
