"""The MCAP files of one station: one file per run, named as :mod:`shared.recordings.layout` says.

A run file is opened by the run's ``ToolState(state="running")`` and holds
what the station publishes from then on: the run, its result and its
summary. A multi-spindle station's cycle is one file: the first spindle's run
to start (its ``ToolState`` names the cycle's ``sync_id``) opens it, named by
that run, and every spindle's run of the cycle goes into it (their states,
samples, events, results, summaries), then the cycle's common result
(``CycleResult``), a grace after which the file is finished (a spindle's
summary does not finish it: the others may still run). A run file is
finished (complete, under its name) ``late_grace_s`` after the run's summary
(its ``RunSummary``), or at the next run's start, whichever comes first: a
station that stops tightening has its last run's file readable a moment
after the run, not at its next run. What the station says after that
(its counters between runs) goes into an idle file (``<station>_idle_...``),
which the next run's start finishes. A message of a run whose file was
finished never opens a file named for that run again: it goes to the idle
file. A file that reaches ``max_file_bytes`` or ``max_file_duration_s`` (a run
that never ends) continues in ``..._part<N>.mcap``. After a rotation the
previous run's file stays open for ``late_grace_s`` so late messages carrying
its run id (a RunSummary racing the next run's start) still land in it.

Files that hear no run's start (``runs_by_id``: what a line predictor's spool
sends again, events to summaries of runs whose files are closed) open a run's
file at the first message of that run, named by that message's time.

With ``rerun`` options each run file (not the idle ones) has a companion
:class:`RerunSink` writing ``<same stem>.rrd``; it receives what its MCAP
file receives, is flushed and closed with it, and never stops the MCAP file.

Each file is written under its writing name and takes its run file's name
when it is closed, complete (:class:`McapSink`'s ``rename_when_complete``): a
reader of the folder never meets a run file being written or left broken.

Below the free-space reserve (:mod:`.free_space`) no file is opened: the
files open are finished and :class:`~.free_space.LowFreeSpaceError` (an
``OSError``) is raised, which the owner takes as a failing disk.

A spooling station's numbered message (:mod:`.spool_filing`) is marked in the
file it went into (:meth:`StationFiles.end_message`; a message split between
two files is marked in neither: sent again after a kill, it may be filed
twice, never lost), which writes the numbers it holds last in each of its
chunks (:mod:`shared.recordings.mcap.spool_marks`).

When the disk fails under a file (an :class:`OSError` out of any method),
the owner (:class:`~services.recorder.live.recorder.Recorder`) calls
:meth:`StationFiles.abandon`; the next write opens a new part of the same run.
"""

from __future__ import annotations

import logging
from collections import OrderedDict, deque
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from services.recorder.live.free_space import FreeSpace
from shared.contract import channels
from shared.recordings import FileMetadata, Received, Sink, file_path
from shared.recordings.mcap import FileMarks, McapSink

if TYPE_CHECKING:  # rerun is imported only when .rrd files are wanted
    from shared.recordings.rerun import RerunOptions, RerunSink

LOG = logging.getLogger(__name__)

#: run ids remembered per station: a ToolState starting one of them again opens no file
STARTED_RUNS_KEPT = 64
#: a multi-spindle station's runs remembered with the file of their cycle (20 spindles, 50
#: cycles: a spool's resend of the newest reaches them)
CYCLE_RUNS_KEPT = 1000
#: a run sent again by a station's spool is named by its start when it is at most this old
SENT_AGAIN_MAX_AGE_NS = 7 * 24 * 3600 * 1_000_000_000
_ENDED_STATES = ("done", "aborted")


@dataclass(frozen=True, slots=True)
class FileLimits:
    """When files are flushed and rotated (integer nanoseconds)."""

    flush_interval_ns: int
    max_file_bytes: int
    max_file_duration_ns: int
    late_grace_ns: int = 2_000_000_000
    fsync: bool = True  # each flush reaches the disk: a power cut loses one interval at most
    #: no new file below this much free space (:mod:`.free_space`); 0: no reserve
    free_space_reserve_bytes: int = 0


@dataclass(frozen=True, slots=True)
class OpenRun:
    """A run's open file, handed from one StationFiles to another (:meth:`~StationFiles.adopt`)."""

    sink: McapSink
    companion: RerunSink | None
    part: int
    ended: bool
    started: tuple[int | None, int]
    tool_id: int | None
    program_id: int | None
    #: when the file is to be finished: a grace after its run's summary (None: at the next run)
    finish_at_ns: int | None = None
    #: a multi-spindle station's: its runs -> the run whose file holds their cycle, and the
    #: cycles' files by sync id (the rest of a cycle, sent again, goes into the same file)
    cycle_runs: tuple[tuple[int, int], ...] = ()
    cycle_files: tuple[tuple[int, int], ...] = ()


class StationFiles:
    """Route one station's payloads into its run files; flush and rotate them."""

    def __init__(
        self,
        station: str,
        folder: Path,
        limits: FileLimits,
        metadata: FileMetadata,
        rerun: RerunOptions | None = None,
        sent_again: bool = False,
        runs_by_id: bool = False,
    ) -> None:
        """``sent_again``: the files of what a station's spool sends again (a hole).
        ``runs_by_id``: a message of a run with no file open here opens that run's file."""
        self.station = station
        self.sent_again = sent_again
        self.runs_by_id = runs_by_id
        self._folder = folder
        self._limits = limits
        self._metadata = metadata
        self._free_space = FreeSpace(folder, limits.free_space_reserve_bytes)
        self.current: McapSink | None = None
        self.previous: McapSink | None = None
        self._previous_until_ns = 0
        self._part = 1
        self._run_ended = False
        self._tool_id: int | None = None
        self._program_id: int | None = None
        self._last_flush_ns = 0
        self.closed_paths: list[Path] = []
        self.abandoned_paths: list[Path] = []
        self.written = 0  # messages handed to a file (flushed or not)
        self.last_path: Path | None = None  # the file of the last message written
        self._resume: tuple[int | None, int] | None = None  # (run_id, part) after abandon()
        self._rerun = rerun
        self._rerun_sinks: dict[McapSink, RerunSink] = {}
        self._run_started: tuple[int | None, int] = (None, 0)  # (run_id, ToolState time_ns)
        self._started_runs: deque[int | None] = deque(maxlen=STARTED_RUNS_KEPT)
        #: when the current run's file is finished: a grace after its summary
        self._finish_at_ns: int | None = None
        #: runs whose file was finished after their summary: never a file of theirs again
        self._finished_runs: deque[int | None] = deque(maxlen=STARTED_RUNS_KEPT)
        #: the files written since :meth:`start_message` (a numbered message's)
        self._touched: set[McapSink] = set()
        self._in_message = False  # between start_message and end_message: no flush
        self._last_now_ns = 0  # the log time of the last message written
        #: a multi-spindle station's runs -> the run whose file holds their cycle
        self._cycle_runs: OrderedDict[int, int] = OrderedDict()
        #: sync id -> the run whose file holds that cycle
        self._cycle_files: OrderedDict[int, int] = OrderedDict()

    def _file_run(self, received: Received) -> int | None:
        """The run whose file ``received`` goes into: its own run, or on a multi-spindle
        station the run that opened its cycle's file (a cycle's common result: its runs')."""
        message = received.message
        if received.run_started and message.sync_id is not None:
            opened = self._cycle_files.get(message.sync_id)
            if opened is None or not (opened == message.run_id or self.holds_run(opened)):
                opened = message.run_id  # the cycle's first run to start: its file's name
                _keep(self._cycle_files, message.sync_id, opened)
            _keep(self._cycle_runs, message.run_id, opened)
            return opened
        run_id = received.run_id
        if run_id is None and received.schema_name == channels.CYCLES.schema_name and message:
            run_id = next(iter(message.run_ids), None)
        if run_id is None or not self._cycle_runs:
            return run_id
        return self._cycle_runs.get(run_id, run_id)

    def write(self, received: Received) -> None:
        now_ns = received.log_time_ns
        run_id = self._file_run(received)
        if received.run_started and self._is_new_run(run_id):
            self._tool_id = received.message.tool_id
            self._program_id = received.message.program_id
            self._run_started = (run_id, received.message.time_ns)
            self._resume = (run_id, 1)  # should the disk fail before the file opens
            self._start_run(run_id, now_ns)
        elif self._opens_its_run(run_id):
            assert run_id is not None
            self._run_started = (run_id, _run_time_ns(received, now_ns))
            self._start_run(run_id, now_ns)
        elif received.schema_name == channels.SAMPLES.schema_name:
            self._open_or_continue(run_id, now_ns, samples_of=run_id)
        else:
            self._open_or_continue(run_id, now_ns)
        assert self.current is not None
        sink = self.current
        previous = self.previous
        if previous is not None and run_id is not None and run_id == previous.run_id != sink.run_id:
            sink = previous
        for target in self._sinks_of(sink):
            target.write(received)
        self._touched.add(sink)
        self.written += 1
        self.last_path = sink.path
        if sink is self.current and received.message is not None:
            schema = received.schema_name
            if schema == channels.TOOL.schema_name:
                self._run_ended = received.message.state in _ENDED_STATES  # a refused one is raw
            elif schema == channels.RUNS.schema_name and run_id == sink.run_id:
                if received.message.sync_id is None:  # a cycle's file waits for its result
                    self._finish_at_ns = now_ns + self._limits.late_grace_ns  # the run is over
            elif schema == channels.CYCLES.schema_name and run_id == sink.run_id:
                self._finish_at_ns = now_ns + self._limits.late_grace_ns  # the cycle is over
        self._flush_if_due(now_ns)

    def write_samples(self, samples: Sequence[Received]) -> None:
        """A batch's decoded Samples, in order: :meth:`write`'s checks once for the batch
        (a sample never starts a run); samples of the run before go to its file."""
        if not samples:
            return
        now_ns = samples[-1].log_time_ns
        run_id = samples[0].message.run_id
        if self._cycle_runs:
            run_id = self._cycle_runs.get(run_id, run_id)
        self._open_or_continue(run_id, now_ns, samples_of=run_id)
        assert self.current is not None
        groups: list[tuple[McapSink, Sequence[Received]]] = [(self.current, samples)]
        previous = self.previous
        if previous is not None and previous.run_id != self.current.run_id:
            late = [s for s in samples if self._file_run_of(s) == previous.run_id]
            if late:
                on_time = [s for s in samples if self._file_run_of(s) != previous.run_id]
                groups = [(previous, late), (self.current, on_time)]
        for sink, group in groups:
            for target in self._sinks_of(sink):
                target.write_samples(group)
            self._touched.add(sink)
            self.written += len(group)
        self._flush_if_due(now_ns)

    def _file_run_of(self, sample: Received) -> int:
        """The run whose file a sample goes into (its own, or its cycle's)."""
        run_id: int = sample.message.run_id
        return self._cycle_runs.get(run_id, run_id) if self._cycle_runs else run_id

    def start_message(self) -> None:
        """A numbered message is about to be filed, perhaps in several parts (a batch: its
        samples, events, intensities): no flush, no chunk ends until :meth:`end_message`."""
        self._touched.clear()
        self._in_message = True
        for sink in (self.current, self.previous):
            if sink is not None:
                sink.hold = True

    def end_message(self, mark: tuple[str, int, int] | None) -> None:
        """The message since :meth:`start_message` is filed: ``mark`` (source, spool id,
        seq; None: not filed whole) is said by the file it went into (by none when it went
        into two, or none); then what was held back: a full chunk ends, a due flush."""
        if mark is not None and len(self._touched) == 1:
            (filed_into,) = self._touched
            if filed_into.marks is None:
                filed_into.marks = FileMarks(self.station)
            filed_into.marks.add(*mark)
        self._touched.clear()
        self._in_message = False
        for sink in (self.current, self.previous):
            if sink is not None:
                sink.hold = False
                sink.end_chunk_if_full()
        self._flush_if_due(self._last_now_ns)

    def _sinks_of(self, sink: McapSink) -> tuple[Sink, ...]:
        """The run file's MCAP sink, then its companions (its ``.rrd``)."""
        companion = self._rerun_sinks.get(sink)
        return (sink,) if companion is None else (sink, companion)

    def _open_or_continue(
        self, run_id: int | None, now_ns: int, samples_of: int | None = None
    ) -> None:
        """A file to write a message of ``run_id`` into (not a run's start): opened when there
        is none (the resumed run's after a fault), continued in a next part past the limits.
        ``samples_of``: samples of that run; in a hole's files (what a spool sends again, in
        order), a run never started there (its start was lost: a disk fault, a spool that
        lost it) gets a file of its own, not the current run's. Live, such samples go into
        the current file (a recorder that joined mid-run; a station whose run ids flip must
        not make a file per sample)."""
        if samples_of and self.sent_again and self._unseen(samples_of):
            LOG.info(
                "%s: samples of run %d, whose start never came: a file of its own",
                self.station,
                samples_of,
            )
            self._started_runs.append(samples_of)
            self._tool_id = self._program_id = None  # not known without the run's start
            self._run_started = (samples_of, now_ns)
            self._resume = (samples_of, 1)
            self._start_run(samples_of, now_ns)
            return
        if self.current is None:
            finished = run_id in self._finished_runs  # its file is done: the idle file's
            resumed_run_id, part = self._resume or (None if finished else run_id, 1)
            self._open(resumed_run_id, now_ns, part)
        elif self._over_limits(now_ns):
            self._continue(now_ns)

    def _flush_if_due(self, now_ns: int) -> None:
        self._last_now_ns = max(self._last_now_ns, now_ns)
        if self._in_message:
            return  # after the message (end_message): its marks go with it
        if now_ns - self._last_flush_ns >= self._limits.flush_interval_ns:
            self.flush(now_ns)

    def tick(self, now_ns: int) -> None:
        """Flush when the flush interval has passed; close the previous file after its grace,
        and the current run's file a grace after its summary."""
        self._flush_if_due(now_ns)
        if self.previous is not None and now_ns >= self._previous_until_ns:
            self._close(self.previous)
            self.previous = None
        finish_at_ns = self._finish_at_ns
        if self.current is not None and finish_at_ns is not None and now_ns >= finish_at_ns:
            self._finish_current()

    def _finish_current(self) -> None:
        """The current run is over (a grace after its summary): its file is finished now; what
        comes next opens an idle file (raising: the owner abandons it)."""
        current = self.current
        assert current is not None
        self._finish_at_ns = None
        self._finished_runs.append(current.run_id)
        self._close(current)
        self.current = None
        LOG.debug("%s finished a grace after its run's summary", current.path)

    def flush(self, now_ns: int) -> None:
        for sink in (self.current, self.previous):
            if sink is not None:
                for target in self._sinks_of(sink):
                    target.flush()
        self._last_flush_ns = now_ns

    def close(self) -> None:
        """Finish every open file of the station."""
        for sink in (self.previous, self.current):
            if sink is not None:
                self._close(sink)
        self.previous = self.current = None

    def abandon(self) -> int:
        """Let go of every open file without writing more (the disk failed); messages lost.

        Never raises. The next write opens a new part of the run that was
        being recorded (what was flushed stays in the abandoned file).
        """
        lost = 0
        for sink in (self.previous, self.current):
            if sink is None:
                continue
            lost += sink.abandon()
            if sink.flushed_messages:
                self.abandoned_paths.append(sink.path)
            companion = self._rerun_sinks.pop(sink, None)
            if companion is not None:
                companion.close()  # never raises
        current = self.current
        if self._resume is None and current is not None:
            finished = current.run_id in self._finished_runs  # failed while being finished
            self._resume = (None if finished else current.run_id, self._part + 1)
        self._finish_at_ns = None
        self.previous = self.current = None
        return lost

    def hand_over(self) -> OpenRun | None:
        """Give away the open file of the run in progress (with its ``.rrd``), and close the
        one before: a station's spool is to send the rest of that run again, into the same
        file, while its newer runs go on here (:meth:`adopt` on the other side)."""
        if self.previous is not None:
            self._close(self.previous)
            self.previous = None
        sink, self.current = self.current, None
        if sink is None:
            return None
        handed = OpenRun(
            sink,
            self._rerun_sinks.pop(sink, None),
            self._part,
            self._run_ended,
            self._run_started,
            self._tool_id,
            self._program_id,
            self._finish_at_ns,
            tuple(self._cycle_runs.items()),
            tuple(self._cycle_files.items()),
        )
        self._finish_at_ns = None
        return handed

    def adopt(self, run: OpenRun | None) -> None:
        """Go on with a run's open file another StationFiles handed over (the files open
        here are finished first)."""
        if run is None:
            return
        self.close()
        self.current = run.sink
        if run.companion is not None:
            self._rerun_sinks[run.sink] = run.companion
        self._part = run.part
        self._run_ended = run.ended
        self._run_started = run.started
        self._tool_id, self._program_id = run.tool_id, run.program_id
        self._finish_at_ns = run.finish_at_ns
        self._started_runs.append(run.sink.run_id)
        for run_id, opened in run.cycle_runs:
            _keep(self._cycle_runs, run_id, opened)
        for sync_id, opened in run.cycle_files:
            _keep(self._cycle_files, sync_id, opened)

    def _opens_its_run(self, run_id: int | None) -> bool:
        """A message of ``run_id`` opens that run's file (``runs_by_id``: none is open)."""
        return self.runs_by_id and run_id is not None and not self.holds_run(run_id)

    def holds_run(self, run_id: int) -> bool:
        """Whether a file of run ``run_id`` (of its cycle's, a multi-spindle station's) is open
        here (the current, or the one before)."""
        if self._cycle_runs:
            run_id = self._cycle_runs.get(run_id, run_id)
        return any(
            sink is not None and sink.run_id == run_id for sink in (self.current, self.previous)
        )

    @property
    def unflushed_messages(self) -> int:
        """Messages of the open files not yet on the disk."""
        return sum(s.unflushed_messages for s in (self.previous, self.current) if s is not None)

    def _unseen(self, run_id: int) -> bool:
        """Samples of ``run_id`` while another run's file is open, a run never started (nor
        finished) here."""
        current, previous = self.current, self.previous
        return (
            current is not None
            and current.run_id != run_id
            and (previous is None or previous.run_id != run_id)
            and run_id not in self._started_runs
            and run_id not in self._finished_runs
        )

    def _is_new_run(self, run_id: int | None) -> bool:
        """A run id starts once: its ToolState flipping back to running opens no new file."""
        if run_id in self._started_runs:
            return False
        self._started_runs.append(run_id)
        return True

    def _start_run(self, run_id: int | None, now_ns: int) -> None:
        if self.previous is not None:
            self._close(self.previous)
        self.previous = self.current
        self._previous_until_ns = now_ns + self._limits.late_grace_ns
        self._finish_at_ns = None  # the previous file's grace is its own now
        self._open(run_id, now_ns, part=1)

    def _continue(self, now_ns: int) -> None:
        """The current file is full: go on with the same run in a new part."""
        assert self.current is not None
        run_id = self.current.run_id
        LOG.info("%s reached its size or duration limit, continuing", self.current.path)
        self._close(self.current)
        self._open(run_id, now_ns, part=self._part + 1)

    def _over_limits(self, now_ns: int) -> bool:
        current = self.current
        assert current is not None
        return (
            current.size_bytes >= self._limits.max_file_bytes
            or now_ns - current.opened_ns >= self._limits.max_file_duration_ns
        )

    def _open(self, run_id: int | None, now_ns: int, part: int) -> None:
        self._part = part
        self._run_ended = False
        self._resume = (run_id, part)  # until the file is open: a failed open is retried as is
        self.current = None  # a run's start moved it to previous already
        try:
            self._free_space.check()
        except OSError:
            self.close()  # the files open now are finished whole: the reserve is for them
            raise
        started_run, started_ns = self._run_started
        named_ns = now_ns
        # a run sent again after a cut opens late: named by its start, as it would have been
        # live, unless the station's clock says something no spool holds
        sent_again_run = self.sent_again and part == 1 and started_run == run_id is not None
        if sent_again_run and 0 <= now_ns - started_ns <= SENT_AGAIN_MAX_AGE_NS:
            named_ns = started_ns
        path = file_path(self._folder, self.station, run_id, named_ns, part)
        tool_id = self._tool_id if run_id is not None else None
        program_id = self._program_id if run_id is not None else None
        metadata = self._metadata.for_file(self.station, run_id, tool_id, program_id)
        self.current = McapSink(
            path,
            metadata,
            run_id,
            now_ns,
            library=f"boltwatch {self._metadata.version}",
            fsync=self._limits.fsync,
            rename_when_complete=True,
        )
        self.current.hold = self._in_message
        self._resume = None
        LOG.debug("opened %s", path)
        if self._rerun is not None and run_id is not None:
            self._open_rerun(path, run_id, now_ns, self._rerun)

    def _open_rerun(self, path: Path, run_id: int, now_ns: int, options: RerunOptions) -> None:
        try:
            from shared.recordings.rerun import open_rerun_sink
        except ImportError:
            LOG.exception("Rerun is unusable; recording MCAP only from now on")
            self._rerun = None
            return
        started_run, started_ns = self._run_started
        if started_run != run_id:  # joined mid-run: the run's start is unknown
            started_ns = now_ns
        companion = open_rerun_sink(path, self.station, run_id, started_ns, options)
        if companion is not None and self.current is not None:
            self._rerun_sinks[self.current] = companion

    def _close(self, sink: McapSink) -> None:
        try:
            sink.close()
        finally:
            companion = self._rerun_sinks.pop(sink, None)
            if companion is not None:
                companion.close()  # never raises: a Rerun failure is logged, not fatal
        self.closed_paths.append(sink.path)


def _keep(remembered: OrderedDict[int, int], key: int, value: int) -> None:
    """``remembered[key] = value``, the oldest let go past :data:`CYCLE_RUNS_KEPT`."""
    remembered[key] = value
    remembered.move_to_end(key)
    while len(remembered) > CYCLE_RUNS_KEPT:
        remembered.popitem(last=False)


def _run_time_ns(received: Received, default_ns: int) -> int:
    """When a run began, as well as one of its messages says (a summary its start, any other
    message its own time)."""
    message = received.message
    started_ns = getattr(message, "started_ns", None)
    if isinstance(started_ns, int):
        return started_ns
    time_ns = getattr(message, "time_ns", None)
    return time_ns if isinstance(time_ns, int) else default_ns
