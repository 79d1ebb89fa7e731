"""Controller runs into the recordings folder, as the live recorder would have written them.

Each :class:`ControllerRun` becomes the messages a live station publishes
(``ToolState`` running, one ``Sample`` per controller sample with
``force_n`` None, ``ToolState`` done) and goes through the recorder's own
:class:`~services.recorder.recorder.Recorder`: same channels, schemas,
metadata records, folders and file names as a live recording, plus a
``controller`` metadata record with the controller's header. Times are the
controller's own: ``time_ns`` = ``date`` + ``time values``, used as both
log and publish time, repeated timestamps and gaps unchanged; ``sequence``
is the sample's index in the run.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from services.recorder.controller_run import ControllerRun
from services.recorder.file_metadata import FileMetadata
from services.recorder.incoming import Received, classify
from services.recorder.recorder import Recorder
from services.recorder.run_files import FileLimits, file_path
from shared import keys
from shared.codec import encode
from shared.errors import InputError
from shared.messages import Sample, ToolState

if TYPE_CHECKING:
    from services.recorder.rerun_sink import RerunOptions

STATION_PATTERN = re.compile(r"^[A-Za-z0-9_-]{1,64}$")
DEFAULT_STATION = "cs351"
#: One chunk per second of controller time; a run is one file (runs last seconds).
IMPORT_LIMITS = FileLimits(
    flush_interval_ns=1_000_000_000,
    max_file_bytes=256 * 1024 * 1024,
    max_file_duration_ns=3600 * 1_000_000_000,
    late_grace_ns=0,
)


@dataclass(frozen=True, slots=True)
class ImportedRun:
    source: Path
    mcap: Path | None  # None: skipped, already in the recordings folder
    rrd: Path | None
    samples: int
    existing: Path | None = None


def check_station_id(station: str) -> str:
    if not STATION_PATTERN.match(station):
        raise InputError(
            f"--station {station!r}: expected 1-64 letters, digits, '_' or '-' (a zenoh key chunk)"
        )
    return station


def already_imported(recordings: Path, station: str, run: ControllerRun) -> Path | None:
    """The file of this run in its day folder, if one is there already."""
    day = file_path(recordings, station, run.run_id, run.started_ns).parent
    return next(iter(sorted(day.glob(f"{station}_run{run.run_id}_*.mcap"))), None)


def controller_messages(station: str, run: ControllerRun) -> list[tuple[str, Any, int]]:
    """(topic, message, time_ns) of the run, in order, as a live station publishes them."""
    times_ns = [run.started_ns + round(t * 1e9) for t in run.time_s]
    out: list[tuple[str, Any, int]] = [
        (keys.TOOL, _state(station, run, "running", run.started_ns), run.started_ns)
    ]
    for sequence, (time_ns, torque, angle) in enumerate(
        zip(times_ns, run.torque_nm, run.angle_deg, strict=True)
    ):
        sample = Sample(station, run.run_id, sequence, time_ns, torque, angle, None)
        out.append((keys.SAMPLES, sample, time_ns))
    end_ns = max(times_ns[-1], run.started_ns) + 1
    out.append((keys.TOOL, _state(station, run, "done", end_ns), end_ns))
    return out


def import_run(
    run: ControllerRun,
    recordings: Path,
    station: str = DEFAULT_STATION,
    rerun: RerunOptions | None = None,
) -> ImportedRun:
    """Write ``run`` under ``recordings`` with the recorder's writing code (skip if there)."""
    existing = already_imported(recordings, station, run)
    if existing is not None:
        return ImportedRun(run.source, None, None, len(run), existing)
    metadata = FileMetadata([], extra={"controller": controller_record(run)}, warn_unknown=False)
    recorder = Recorder(recordings, IMPORT_LIMITS, metadata, rerun)
    try:
        for topic, message, time_ns in controller_messages(station, run):
            recorder.write(_received(station, topic, message, time_ns))
    finally:
        closed = recorder.close()
    (mcap,) = closed
    rrd = mcap.with_suffix(".rrd")
    return ImportedRun(run.source, mcap, rrd if rrd.is_file() else None, len(run))


def controller_record(run: ControllerRun) -> dict[str, str]:
    """The ``controller`` metadata record: where the run came from and its header."""
    record = {
        "source_file": run.source.name,
        "date_timezone": "none in the file; taken as UTC",
        "steps": ",".join(run.step_names),
        "samples": str(len(run)),
    }
    record.update(run.header)
    return record


def _state(station: str, run: ControllerRun, state: Any, time_ns: int) -> ToolState:
    return ToolState(station, run.run_id, run.tool_id, run.program_id, state, time_ns)


def _received(station: str, topic: str, message: Any, time_ns: int) -> Received:
    return classify(keys.station_key(station, topic), encode(message), time_ns)
