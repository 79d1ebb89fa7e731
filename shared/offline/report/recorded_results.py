"""The tightening results (and run summaries) of stations in a time range: from the results
store (:func:`read_stored`), or from the recordings themselves (:func:`read_results`).

Reads ``<recordings>/<station>/<YYYY-MM-DD>/*.mcap`` (the layout of
:mod:`shared.recordings.layout`, dates in UTC) for the days of the
range, every complete message of channels ``results`` and ``runs``, damaged
files as far as they go (:class:`RecordingScan`, a warning each). A file
that cannot be read at all (empty, cut inside its header, not MCAP, not a
regular file, a symlink loop) is named, skipped and counted (a recordings
folder that is a symlink loop: one line, InputError); a payload that does not decode
(a Sample where a result belongs, ``{}``, binary) is refused and counted,
the file's other messages still read. A result is kept when it ended
(``time_ns``) inside the range, matches the program / tool asked for and
can be a measurement (:func:`shared.quality.implausible`: refused and
counted otherwise, from the store too). The same result seen twice (a file
and its ``.recovered`` copy) counts once. Either way what comes is each program's
columns (what the report's statistics read): the store gives the same
columns as the files, each result with the events of its run (what a
summary adds to a result from the files), in a few statements instead of a
read of every file.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from datetime import date, datetime, timedelta
from pathlib import Path

from shared.contract import RunSummary, TighteningResult, channels, decode
from shared.errors import InputError
from shared.quality import ProgramColumns, columns_of, implausible, refusal_line
from shared.recordings import loop_lines, recording_files, station_days
from shared.recordings.mcap import RecordingScan
from shared.results import ResultsQuery, ResultsStore, program_columns, time_ns_of

#: progress is told every this many files (when there are more)
PROGRESS_EVERY_FILES = 50


@dataclass(frozen=True, slots=True)
class ResultFilter:
    """Which results a report is about: stations, a range of end times, a program, a tool."""

    stations: Sequence[tuple[str, Path]]  # (station id, its recordings folder)
    since: datetime | None = None  # UTC; None: from the first recording
    until: datetime | None = None  # UTC, exclusive; None: up to now
    program_id: int | None = None
    tool_id: int | None = None

    @property
    def since_ns(self) -> int | None:
        return None if self.since is None else time_ns_of(self.since)

    @property
    def until_ns(self) -> int | None:
        return None if self.until is None else time_ns_of(self.until)

    def keeps(self, result: TighteningResult) -> bool:
        """Whether ``result`` is in the range (to the nanosecond, as the store's query) and
        of the program and tool asked for."""
        since_ns, until_ns = self.since_ns, self.until_ns
        return (
            (since_ns is None or result.time_ns >= since_ns)
            and (until_ns is None or result.time_ns < until_ns)
            and (self.program_id is None or result.program_id == self.program_id)
            and (self.tool_id is None or result.tool_id == self.tool_id)
        )


@dataclass
class RecordedResults:
    """What was read: each program's columns (:mod:`shared.quality.program_columns`), the
    files and the damaged ones."""

    programs: list[ProgramColumns] = field(default_factory=list)
    files: int = 0
    damaged: list[str] = field(default_factory=list)  # one line per damaged file
    skipped: list[str] = field(default_factory=list)  # one line per file not read at all
    refused: list[str] = field(default_factory=list)  # one line per payload or result refused

    @property
    def results(self) -> int:
        return sum(program.runs for program in self.programs)


def files_in_range(
    station: str, folder: Path, rule: ResultFilter, loops: list[Path] | None = None
) -> list[Path]:
    """The MCAP files of ``station`` under ``folder`` whose day folder may hold the range
    (a day either side: a file opened before midnight holds runs that ended after it);
    symlink loops met on the way: in ``loops`` (``folder`` one: InputError)."""
    first: date | None = rule.since.date() - timedelta(days=1) if rule.since else None
    last: date | None = rule.until.date() + timedelta(days=1) if rule.until else None
    files: list[Path] = []
    for day_date, day in station_days(folder, station, loops):
        if (first and day_date < first) or (last and day_date > last):
            continue
        files.extend(recording_files(day, loops=loops))
    return files


def read_results(
    rule: ResultFilter, progress: Callable[[int, int], None] | None = None
) -> RecordedResults:
    """Every result that ``rule`` keeps, in the order the runs ended; ``progress(done,
    total)`` is called every :data:`PROGRESS_EVERY_FILES` files and at the end."""
    loops: list[Path] = []
    files = [
        (station, path)
        for station, folder in rule.stations
        for path in files_in_range(station, folder, rule, loops)
    ]
    results: list[TighteningResult] = []
    #: (station, run id, tool id) -> its RunSummary (events per run when a result has none)
    summaries: dict[tuple[str, int, int], RunSummary] = {}
    read = RecordedResults(files=len(files), skipped=loop_lines(loops))
    seen: set[tuple[str, int, int, int]] = set()
    for done, (station, path) in enumerate(files, start=1):
        try:
            _read_file(path, station, rule, (results, summaries, seen), read)
        except InputError as err:  # not a recording at all: named, skipped, counted
            read.skipped.append(str(err))
        if progress is not None and (done % PROGRESS_EVERY_FILES == 0 or done == len(files)):
            progress(done, len(files))
    results.sort(key=lambda result: (result.time_ns, result.station, result.run_id))
    read.programs = columns_of(results, summaries)
    return read


_Found = tuple[
    list[TighteningResult],
    dict[tuple[str, int, int], RunSummary],
    set[tuple[str, int, int, int]],
]


def _read_file(
    path: Path, station: str, rule: ResultFilter, found: _Found, read: RecordedResults
) -> None:
    """The results and summaries of one file into ``found`` (results, summaries, keys seen),
    what was refused or damaged into ``read``; InputError: not readable at all."""
    results, summaries, seen = found
    result_topic, runs_topic = channels.RESULTS.topic, channels.RUNS.topic
    scan = RecordingScan(path)
    for _, channel, message in scan.typed_messages():  # a refused payload is no result
        topic = channel.topic.rsplit("/", 1)[-1]
        if not channel.topic.startswith(f"boltwatch/{station}/") or topic not in (
            result_topic,
            runs_topic,
        ):
            continue
        try:
            if topic == result_topic:
                result = decode(TighteningResult, message.data)
            else:
                summary = decode(RunSummary, message.data)
        except InputError as err:
            read.refused.append(f"{path}: message {message.sequence} on {channel.topic}: {err}")
            continue
        if topic == runs_topic:
            summaries[(summary.station, summary.run_id, summary.tool_id)] = summary
            continue
        key = (result.station, result.run_id, result.tool_id, result.time_ns)
        if key in seen or not rule.keeps(result):
            continue
        seen.add(key)
        why = implausible(result)
        if why is None:
            results.append(result)
        else:
            read.refused.append(refusal_line(result.station, result.run_id, result.tool_id, why))
    if not scan.complete:
        read.damaged.append(scan.describe())


def read_stored(store: ResultsStore, rule: ResultFilter) -> RecordedResults:
    """Every result that ``rule`` keeps, from the results store, in the order the runs ended."""
    query = ResultsQuery(
        stations=[station for station, _ in rule.stations],
        program_id=rule.program_id,
        tool_id=rule.tool_id,
        since_ns=rule.since_ns,
        until_ns=rule.until_ns,
        limit=None,
        oldest_first=True,
    )
    read = program_columns(store, query)
    return RecordedResults(read.programs, refused=read.refused)
