"""Results from recordings into the store: ``boltwatch results rebuild``, and the
recorder's catch-up at start.

Each MCAP file is read once for its ``results`` (and ``runs``: the events of
a result that has none; ``cycles``: a multi-spindle cycle's common result) and
every result stored (idempotent, so a file read
again adds nothing twice). A file read whole is marked with its size and
modification time in ``recordings_read``, so the next reading skips it
unless it changed: a rebuild stopped halfway goes on where it stopped. A
damaged file (a recorder killed mid-write, a cut cable) is read as far as it
goes, warned of, and not marked: it is read again next time. A payload the
recorder refused (kept raw on the topic's raw channel) is no result; one on a
typed channel that does not decode (a file not written by our recorder: a
Sample where a result belongs, ``{}``, binary) is refused and counted, the
file's other results stored. A result whose figures cannot be a measurement is
no result: the store keeps it aside (:mod:`.refused_results`), and it is named
and counted with the refused payloads. A file that cannot be read at all
(empty, not MCAP, not a regular file) is named, skipped and counted.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from datetime import date
from pathlib import Path

from shared.config import StationPlace
from shared.contract import CycleResult, RunSummary, TighteningResult, channels, decode
from shared.errors import InputError
from shared.recordings import recording_files, station_days
from shared.recordings.mcap import RecordingScan
from shared.results.results_store import ResultsStore
from shared.results.stored_result import StoredResult, stored_result

_RESULTS = "/" + channels.RESULTS.topic
_RUNS = "/" + channels.RUNS.topic
_CYCLES = "/" + channels.CYCLES.topic


@dataclass
class FillCounts:
    """What a reading of recordings did."""

    files: int = 0  # files it was given
    done: int = 0  # of them, looked at so far
    read: int = 0  # files it read (not skipped as read before)
    results: int = 0  # results found in what it read (not those refused)
    new: int = 0  # of them, new to the store
    damaged: list[str] = field(default_factory=list)  # one line per damaged file
    skipped: list[str] = field(default_factory=list)  # one line per file not read at all
    #: one line per payload refused, and per result whose figures cannot be a measurement
    refused: list[str] = field(default_factory=list)
    refused_results: int = 0  # of them, results (kept aside by the store)


def station_recordings(
    folder: Path,
    stations: Iterable[str],
    first_day: date | None = None,
    loops: list[Path] | None = None,
) -> list[Path]:
    """Every MCAP file of ``stations`` under the recordings ``folder``, oldest day first
    (``first_day``: only the day folders from it on); symlink loops met on the way: skipped,
    in ``loops`` (``folder`` one: InputError)."""
    return [
        path
        for station in stations
        for day_date, day in station_days(folder, station, loops)
        if first_day is None or day_date >= first_day
        for path in recording_files(day, loops=loops)
    ]


def results_of(
    path: Path,
    places: Mapping[str, StationPlace],
    host: str,
    now_ns: int,
    refused: list[str] | None = None,
    cycles: list[CycleResult] | None = None,
) -> tuple[list[StoredResult], RecordingScan]:
    """The results recorded in ``path`` (as far as it is readable), as the store keeps them:
    where each station is from ``places`` (one not in it: nowhere named), the file as their
    recording; a payload that does not decode is left out (a line in ``refused`` each); the
    multi-spindle cycles' common results it holds go into ``cycles``. InputError: not
    readable."""
    scan = RecordingScan(path)
    results: list[TighteningResult] = []
    summaries: dict[tuple[str, int], RunSummary] = {}
    for _, channel, message in scan.typed_messages():  # a refused payload is no result
        try:
            if channel.topic.endswith(_RESULTS):
                results.append(decode(TighteningResult, message.data))
            elif channel.topic.endswith(_RUNS):
                summary = decode(RunSummary, message.data)
                summaries[(summary.station, summary.run_id)] = summary
            elif channel.topic.endswith(_CYCLES) and cycles is not None:
                cycles.append(decode(CycleResult, message.data))
        except InputError as err:
            if refused is not None:
                refused.append(f"{path}: message {message.sequence} on {channel.topic}: {err}")
    recording = str(path.resolve())
    stored = [
        stored_result(
            result,
            place.line,
            recording,
            host,
            now_ns,
            summaries.get((result.station, result.run_id)),
            plant=place.plant,
            station_name=place.name,
        )
        for result in results
        for place in [places.get(result.station, StationPlace())]
    ]
    return stored, scan


def fill_from_recordings(
    store: ResultsStore,
    files: Sequence[Path],
    places: Mapping[str, StationPlace],
    host: str,
    clock_ns: Callable[[], int],
    progress: Callable[[FillCounts], None] | None = None,
) -> FillCounts:
    """Store the results of ``files`` (those read whole before and unchanged since: skipped);
    ``progress`` is told after each file."""
    counts = FillCounts(files=len(files))
    for path in files:
        try:
            stat = path.stat()
        except FileNotFoundError:  # gone since it was listed (a retention policy, a person)
            counts.done += 1
            continue
        recording = str(path.resolve())
        if store.recording_read(host, recording) != (stat.st_size, stat.st_mtime_ns):
            cycles: list[CycleResult] = []
            try:
                stored, scan = results_of(path, places, host, clock_ns(), counts.refused, cycles)
            except InputError as err:
                counts.skipped.append(str(err))
            else:
                counts.read += 1
                refused = len(counts.refused)
                counts.new += store.add(stored, counts.refused)
                if cycles:
                    store.add_cycles(cycles, clock_ns())
                counts.refused_results += len(counts.refused) - refused
                counts.results += len(stored) - (len(counts.refused) - refused)
                if scan.complete:
                    store.mark_read(
                        host, recording, stat.st_size, stat.st_mtime_ns, len(stored), clock_ns()
                    )
                else:
                    counts.damaged.append(scan.describe())
        counts.done += 1
        if progress is not None:
            progress(counts)
    return counts
