"""The recorder's logic, free of zenoh: received payloads in, MCAP files out.

:class:`Recorder` keeps one :class:`StationFiles` per station seen (the
recorder subscribes to the whole line), counts per station the payloads it
refused (:mod:`.incoming`: still recorded raw) and those on keys that are no
message of ours (logged once, then at most every 10 s: a flood of bad
payloads is never a line per message) and is driven by a clock tick so
files are flushed even when nothing arrives.

Recording is not on the stop path: a disk that fails under it (full,
read-only, an I/O error: any :class:`OSError` on open, write, flush or close)
never stops the recorder. The station's open files are abandoned (what was
flushed stays under the file's writing name; :meth:`Recorder.close`, or the
next start if it cannot, makes it the run file), messages are dropped
and counted, and writing is tried again at the next run's start or every
:data:`RETRY_INTERVAL_NS`; a disk that was full (``ENOSPC``, ``EDQUOT``, below
the reserve) is tried again as soon as it has room (its free space, one
``statvfs`` at most every :data:`ROOM_CHECK_INTERVAL_NS`, back above the
reserve, or :data:`ROOM_BYTES` without one), so the run in progress is
recorded from where room came back. It logs one ERROR when the fault starts (file and
errno text), a reminder with the count of dropped messages at most every
:data:`REMINDER_INTERVAL_NS`, and one INFO when writing works again (a flush
reached the disk). ``write_errors``, ``last_write_error`` and
``recording_ok`` say the same to whoever publishes the recorder's state.
Free space below the reserve (:mod:`.free_space`) is such a fault, met
before the disk is full: no new file is opened, none is cut.

What a source that starts no runs (a line predictor) sends again goes into the
open file of its run (:meth:`Recorder.files_of_run`), else into files of the
station's own for such messages, a file per run, finished once nothing came for
:data:`LATE_FILES_IDLE_NS`.
"""

from __future__ import annotations

import errno
import logging
from collections import Counter
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

from services.recorder.live.free_space import FreeSpace
from services.recorder.live.run_files import FileLimits, StationFiles
from shared.files import describe_os_error
from shared.recordings import FileMetadata, Received, writing_path
from shared.recordings.mcap import finish_one
from shared.runtime import RateLimitedLog

if TYPE_CHECKING:
    from shared.recordings.rerun import RerunOptions

LOG = logging.getLogger(__name__)

RETRY_INTERVAL_NS = 3_000_000_000
REMINDER_INTERVAL_NS = 10_000_000_000
#: a station's files of late messages are finished when nothing came for them this long
LATE_FILES_IDLE_NS = 10_000_000_000
#: a full disk's free space is looked at this often while it is full
ROOM_CHECK_INTERVAL_NS = 100_000_000
#: free space that is room again when there is no reserve
ROOM_BYTES = 256 * 1024
_FULL = (errno.ENOSPC, errno.EDQUOT)


class Recorder:
    """File every received payload into its station's run files."""

    def __init__(
        self,
        folder: Path,
        limits: FileLimits,
        metadata: FileMetadata,
        rerun: RerunOptions | None = None,
    ) -> None:
        self._folder = folder
        self._rerun = rerun
        self._limits = limits
        self._metadata = metadata
        self._stations: dict[str, StationFiles] = {}
        self._holes: list[StationFiles] = []  # the files of holes of stations' spools
        #: per station, files of late messages of runs no file is open for (among the holes'
        #: files), with how many they had written and since when
        self._late: dict[str, tuple[StationFiles, int, int]] = {}
        self._closed_holes: list[Path] = []
        self.messages = 0
        self.refused: Counter[str] = Counter()  # per station: refused payloads, recorded raw
        self.unknown_keys: Counter[str] = Counter()  # per station: not a message key, raw
        self._log_refused = RateLimitedLog(LOG)
        self._log_unknown = RateLimitedLog(LOG)
        self.write_errors = 0  # OSErrors met on open/write/flush/close
        self.last_write_error: str | None = None
        self.recording_ok = True
        self.dropped_messages = 0  # received but not recorded, because the disk failed
        self._fault_started_ns = 0
        self._fault_dropped = 0
        self._retry_at_ns = 0
        self._remind_at_ns = 0
        self._full = False  # the fault is a full disk: tried again once it has room
        self._room = FreeSpace(folder, max(limits.free_space_reserve_bytes, ROOM_BYTES))
        self._room_checked_ns = 0

    def write(self, received: Received, files: StationFiles | None = None) -> Path | None:
        """File one received message into its station's live files (or ``files``: the
        files of a hole of the station's spool, :meth:`hole_files`); the file it went
        into (None: dropped, the disk failing)."""
        files = files or self._files(received.station)
        if not received.decodable:
            self.refused[received.station] += 1
            self._log_refused(
                "payload on %s refused, recorded raw (#%d of %s): %s",
                received.key,
                self.refused[received.station],
                received.station,
                received.problem,
            )
        elif received.schema_name is None:
            self.unknown_keys[received.station] += 1
            self._log_unknown("%s is not a boltwatch message key; recording it raw", received.key)
        self.messages += 1
        now_ns = received.log_time_ns
        if self._waits_for_retry(files, now_ns) and not received.run_started:
            self._drop(1, now_ns)
            return None
        written_before = files.written
        try:
            files.write(received)
        except OSError as err:  # a message already in the file is counted by abandon()
            self._fault(files, err, now_ns, unwritten=int(files.written == written_before))
            return None
        self._maybe_recovered(files, now_ns)
        return files.last_path

    def write_samples(
        self, station: str, samples: Sequence[Received], files: StationFiles | None = None
    ) -> None:
        """The decoded Samples of one batch of ``station``, as :meth:`write` files each."""
        if not samples:
            return
        files = files or self._files(station)
        self.messages += len(samples)
        now_ns = samples[-1].log_time_ns
        if self._waits_for_retry(files, now_ns):
            self._drop(len(samples), now_ns)
            return
        written_before = files.written
        try:
            files.write_samples(samples)
        except OSError as err:  # samples already in a file are counted by abandon()
            unwritten = len(samples) - (files.written - written_before)
            self._fault(files, err, now_ns, unwritten=unwritten)
            return
        self._maybe_recovered(files, now_ns)

    def live_files(self, station: str) -> StationFiles:
        """The live files of ``station`` (where its messages go outside a spool's hole)."""
        return self._files(station)

    def end_message(
        self, files: StationFiles, mark: tuple[str, int, int] | None, now_ns: int
    ) -> None:
        """``files`` filed a numbered message received at ``now_ns``
        (:meth:`StationFiles.end_message`: its mark, then the flush held back meanwhile)."""
        try:
            files.end_message(mark)
        except OSError as err:
            self._fault(files, err, now_ns, unwritten=0)
        else:
            self._maybe_recovered(files, now_ns)

    def hole_files(self, station: str, hand_over: bool) -> StationFiles:
        """Files for a hole of ``station``'s spool (``hand_over``: they go on with the run the
        live files were recording, and the live files start afresh)."""
        files = StationFiles(
            station, self._folder, self._limits, self._metadata, self._rerun, sent_again=True
        )
        if hand_over:
            files.adopt(self._files(station).hand_over())
        self._holes.append(files)
        return files

    def hand_back(self, files: StationFiles) -> None:
        """A hole caught up with the live messages: the live files go on with its open run."""
        self._files(files.station).adopt(files.hand_over())

    def files_of_run(self, station: str, run_id: int | None) -> StationFiles:
        """Where a message of run ``run_id`` of ``station``, sent again by a source that starts
        no runs, goes: the files (live, or a hole's) that have its run open; else the
        station's files of late messages (a file of the run of their own). No run: the live
        files."""
        live = self._files(station)
        if run_id is None:
            return live
        for files in (live, *self._holes):
            if files.station == station and files.holds_run(run_id):
                return files
        late = self._late.get(station)
        if late is None:
            files = StationFiles(
                station, self._folder, self._limits, self._metadata, None, True, runs_by_id=True
            )
            self._holes.append(files)
            late = self._late[station] = (files, 0, 0)
        return late[0]

    def _finish_idle_late_files(self, now_ns: int) -> None:
        for station, (files, written, since_ns) in list(self._late.items()):
            if files.written != written or not since_ns:
                self._late[station] = (files, files.written, now_ns)
            elif now_ns - since_ns >= LATE_FILES_IDLE_NS:
                del self._late[station]
                self.close_hole(files)

    def close_hole(self, files: StationFiles) -> None:
        """The hole is filled: its files are finished."""
        if files in self._holes:
            self._holes.remove(files)
        try:
            files.close()
        except OSError as err:
            self._fault(files, err, self._fault_started_ns, unwritten=0)
        self._closed_holes.extend(files.closed_paths)

    def flush(self, station: str, now_ns: int) -> bool:
        """What ``station``'s files (live and holes) hold reaches the disk now; False when
        writing failed (nothing more of it can be taken as written)."""
        ok = True
        for files in [self._files(station), *(f for f in self._holes if f.station == station)]:
            try:
                files.flush(now_ns)
            except OSError as err:
                self._fault(files, err, now_ns, unwritten=0)
                ok = False
            else:  # a file written after a fault is on the disk now: writing works again
                self._maybe_recovered(files, now_ns)
        return ok and self.recording_ok

    def tick(self, now_ns: int) -> None:
        for files in [*self._stations.values(), *self._holes]:
            try:
                files.tick(now_ns)
            except OSError as err:
                self._fault(files, err, now_ns, unwritten=0)
            else:
                self._maybe_recovered(files, now_ns)
        self._finish_idle_late_files(now_ns)
        if not self.recording_ok:
            self._remind(now_ns)

    def close(self) -> list[Path]:
        """Finish every open file; the paths of every file closed so far."""
        closed: list[Path] = list(self._closed_holes)
        for files in [*self._holes, *self._stations.values()]:
            try:
                files.close()
            except OSError as err:
                self._fault(files, err, self._fault_started_ns, unwritten=0)
            closed.extend(files.closed_paths)
        closed.extend(self._finish_abandoned())
        if self.refused:
            LOG.warning("refused payloads per station, recorded raw: %s", dict(self.refused))
        if self.dropped_messages:
            LOG.error(
                "%d messages were not recorded because writing failed (last: %s); "
                "incomplete files: %s",
                self.dropped_messages,
                self.last_write_error,
                ", ".join(str(path) for path in self.abandoned_files) or "-",
            )
        return closed

    def _finish_abandoned(self) -> list[Path]:
        """The files a write fault abandoned, made run files (valid, under their names) if
        the disk lets it now; else the next start does."""
        finished = []
        for path in self.abandoned_files:
            if writing_path(path).is_file():
                done = finish_one(writing_path(path))
                if done.final is not None:
                    finished.append(done.final)
        return finished

    def open_paths(self) -> list[Path]:
        """The MCAP files open now (every station's current and previous, every hole's)."""
        return [
            sink.path
            for files in [*self._stations.values(), *self._holes]
            for sink in (files.current, files.previous)
            if sink is not None
        ]

    @property
    def abandoned_files(self) -> list[Path]:
        """Files left incomplete by a write fault (``boltwatch recover`` makes them valid)."""
        return [path for files in self._stations.values() for path in files.abandoned_paths]

    def _waits_for_retry(self, files: StationFiles, now_ns: int) -> bool:
        """Writing failed and the station's files were abandoned, not tried again yet: what
        arrives is dropped (a run's start tries at once, and so does a full disk that has
        room again)."""
        waits = not self.recording_ok and files.current is None and now_ns < self._retry_at_ns
        return waits and not self._room_again(now_ns)

    def _room_again(self, now_ns: int) -> bool:
        """A full disk has room again (its free space looked at now and then)."""
        if not self._full or now_ns - self._room_checked_ns < ROOM_CHECK_INTERVAL_NS:
            return False
        self._room_checked_ns = now_ns
        try:
            return self._room.free_bytes() >= self._room.reserve_bytes
        except OSError:
            return False

    def _files(self, station: str) -> StationFiles:
        files = self._stations.get(station)
        if files is None:
            files = StationFiles(station, self._folder, self._limits, self._metadata, self._rerun)
            self._stations[station] = files
        return files

    def _fault(self, files: StationFiles, err: OSError, now_ns: int, *, unwritten: int) -> None:
        """``unwritten``: messages being written that never reached a file (lost too)."""
        path = files.current.path if files.current is not None else None
        self.write_errors += 1
        self.last_write_error = describe_os_error(err, path)
        lost = files.abandon() + unwritten
        self._retry_at_ns = now_ns + RETRY_INTERVAL_NS
        self._full = err.errno in _FULL
        self._room_checked_ns = now_ns
        if self.recording_ok:
            self.recording_ok = False
            self._fault_started_ns = now_ns
            self._fault_dropped = 0
            self._remind_at_ns = now_ns + REMINDER_INTERVAL_NS
            LOG.error(
                "recording failed: %s; station %s: messages are dropped and counted, "
                "writing is retried at the next run or every %.0f s "
                "(what reached the incomplete file is kept: it is made valid when the "
                "recorder stops or starts)",
                self.last_write_error,
                files.station,
                RETRY_INTERVAL_NS / 1e9,
            )
        self._drop(lost, now_ns)

    def _drop(self, count: int, now_ns: int) -> None:
        self.dropped_messages += count
        self._fault_dropped += count
        self._remind(now_ns)

    def _remind(self, now_ns: int) -> None:
        if now_ns < self._remind_at_ns:
            return
        self._remind_at_ns = now_ns + REMINDER_INTERVAL_NS
        LOG.error(
            "recording still failing for %.0f s: %d messages dropped so far (last error: %s)",
            (now_ns - self._fault_started_ns) / 1e9,
            self._fault_dropped,
            self.last_write_error,
        )

    def _maybe_recovered(self, files: StationFiles, now_ns: int) -> None:
        """Writing works again once a file is open and everything in it reached the disk."""
        if self.recording_ok or files.current is None or files.unflushed_messages:
            return
        self.recording_ok = True
        LOG.info(
            "recording works again into %s after %.1f s; %d messages were dropped meanwhile",
            files.current.path,
            (now_ns - self._fault_started_ns) / 1e9,
            self._fault_dropped,
        )
