"""A run's curve for the page, read from its recording off the event loop, bounded and cached.

Reading an MCAP file is CPU work (mcap's pure-Python reader, a JSON decode a message:
some 15 ms for a run of 3000 samples on a quiet machine), so it runs in a pool of
:data:`READERS` threads of its own, each below the line's services in the kernel's eyes
(nice :data:`READER_NICE`: a recorder on the same box is never kept from the CPU by a
browser), never on the event loop: the page's live updates go on meanwhile.

What a flood of requests can do is bounded: at most :data:`READERS` jobs run and
:data:`WAITING` more wait; one more is answered 503 at once ("ask again in a moment",
``Retry-After: 1``), counted in :attr:`RunViews.refused`. Requests for a run being read
share that reading (several people opening one NOK run read it once), and a run read is
kept (:mod:`.run_cache`) until its files change. A job that a browser gave up on runs to
its end, and holds its place until then.

The jobs, each in one worker:

- :meth:`RunViews.view`: the run's view (its files located by :mod:`.run_locator`,
  read by :func:`~shared.offline.post_mortem.read_run_files`, drawn as data by
  :func:`~shared.offline.post_mortem.run_document`), gzipped JSON; a run just ended
  whose file the recorder has not flushed yet (under its writing name, its result not
  stored) is ``pending``: the page asks again;
- :meth:`RunViews.part`: every tightening of the run's part overlaid (at most
  :data:`PART_RUNS`);
- :meth:`RunViews.band`: the run against its program's last OK runs at its station;
- :meth:`RunViews.cycle`: a multi-spindle station's run with every spindle's run of its
  cycle overlaid (:mod:`.cycle_runs`);
- :meth:`RunViews.located`: the run's files, for a download.

Every refusal is a :class:`~.run_locator.RunRequestError` with its status and one line.
"""

from __future__ import annotations

import asyncio
import logging
import os
import threading
from collections.abc import Callable, Sequence
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from typing import Any, TypeVar

from services.dashboard.cycle_runs import cycle_document, with_spindles
from services.dashboard.json_replies import gzipped_json
from services.dashboard.run_cache import ReadRun, RunCache
from services.dashboard.run_locator import LocatedRun, RunLocator, RunRequestError
from shared.errors import InputError, StoreError
from shared.files import real_path
from shared.offline.overlay import (
    Alignment,
    OverlayRun,
    overlay_run_of,
    part_overlay_document,
    program_band_document,
)
from shared.offline.post_mortem import RecordedRun, read_run_files, run_document
from shared.recordings import rerun_path
from shared.results.results_table import as_dict

LOG = logging.getLogger(__name__)

#: runs read at once, and requests waiting for a reader at most
READERS = 2
WAITING = 16
#: the readers' nice value (a thread's own on Linux): below the services on the box
READER_NICE = 10
#: a part's tightenings overlaid at most, the newest
PART_RUNS = 32

T = TypeVar("T")
Reader = Callable[[Sequence[Path], int], RecordedRun]


def _below_the_services() -> None:
    """A reader thread's start: its nice value raised (Linux keeps one per thread)."""
    try:
        os.setpriority(os.PRIO_PROCESS, threading.get_native_id(), READER_NICE)
    except OSError as err:
        LOG.info("a run reader keeps its priority (%s)", err)


def download_files(located: LocatedRun) -> dict[str, tuple[str, Path]]:
    """The run's files a browser may download, by name: each MCAP file (``mcap``), and the
    Rerun recording beside a finished one (``rrd``) when it is a regular file in the same
    real folder."""
    found: dict[str, tuple[str, Path]] = {}
    for path in located.files:
        found[path.name] = ("mcap", path)
        rerun = rerun_path(path)
        beside = path.name.endswith(".mcap") and rerun.is_file()
        if beside and real_path(rerun).parent == real_path(path).parent:
            found[rerun.name] = ("rrd", rerun)
    return found


def downloads(located: LocatedRun) -> list[dict[str, Any]]:
    """The run's downloads as the view lists them: name, kind, bytes."""
    return [
        {"name": name, "kind": kind, "bytes": _size(path)}
        for name, (kind, path) in download_files(located).items()
    ]


def _size(path: Path) -> int | None:
    try:
        return path.stat().st_size
    except OSError:
        return None


class RunViews:
    """The page's reading of runs (see the module docstring)."""

    def __init__(
        self,
        locator: RunLocator,
        *,
        readers: int = READERS,
        waiting: int = WAITING,
        cache: RunCache | None = None,
        read: Reader = read_run_files,
        viewers: dict[str, str | None] | None = None,
    ) -> None:
        self.locator = locator
        self.cache = cache or RunCache()
        self.readers = readers
        self.bound = readers + waiting
        self.refused = 0  # requests answered 503: every place taken
        self.viewers = viewers or {}  # templates of links to outside viewers, for the view
        self._read = read
        self._executor = ThreadPoolExecutor(
            readers, thread_name_prefix="run-reader", initializer=_below_the_services
        )
        self._slots: asyncio.Semaphore | None = None
        self._inside = 0  # admitted: running or waiting for a reader
        self._pending: dict[tuple[str, int], asyncio.Future[bytes]] = {}

    def close(self) -> None:
        """Stop taking jobs; those running end on their own (their threads are not joined)."""
        self._executor.shutdown(wait=False, cancel_futures=True)

    async def view(self, station: str, run_id: int) -> bytes:
        """The run's view, gzipped JSON (one reading shared by every request meanwhile)."""
        key = (station, run_id)
        pending = self._pending.get(key)
        if pending is None:
            pending = asyncio.ensure_future(self._admitted(lambda: self._load(*key).view_gz))
            self._pending[key] = pending
            pending.add_done_callback(lambda done: self._settled(key, done))
        return await asyncio.shield(pending)

    async def part(self, station: str, run_id: int, alignment: Alignment) -> bytes:
        """Every tightening of the run's part overlaid (gzipped JSON)."""
        return await self._admitted(lambda: self._part(station, run_id, alignment))

    async def band(self, station: str, run_id: int, runs: int, alignment: Alignment) -> bytes:
        """The run against its program's last ``runs`` OK runs at its station (gzipped JSON)."""
        return await self._admitted(lambda: self._band(station, run_id, runs, alignment))

    async def cycle(self, station: str, run_id: int, alignment: Alignment) -> bytes:
        """Every spindle's run of the run's multi-spindle cycle overlaid (gzipped JSON)."""
        return await self._admitted(lambda: self._cycle(station, run_id, alignment))

    async def located(self, station: str, run_id: int) -> LocatedRun:
        """The run's files (a download's)."""
        return await self._admitted(lambda: self.locator.locate(station, run_id))

    async def _admitted(self, work: Callable[[], T]) -> T:
        """``work`` in a reader once one is free; 503 at once when every place is taken."""
        if self._inside >= self.bound:
            self.refused += 1
            raise RunRequestError(
                503,
                f"the page is reading {self._inside} runs for others: ask again in a moment",
            )
        if self._slots is None:
            self._slots = asyncio.Semaphore(self.readers)
        slots = self._slots
        self._inside += 1
        try:
            await slots.acquire()
        except BaseException:
            self._inside -= 1
            raise
        future = asyncio.get_running_loop().run_in_executor(self._executor, work)
        future.add_done_callback(lambda done: self._freed(slots, done))
        return await asyncio.shield(future)

    def _freed(self, slots: asyncio.Semaphore, done: asyncio.Future[Any]) -> None:
        """A job ended (given up on or not): its place is free."""
        slots.release()
        self._inside -= 1
        if not done.cancelled():
            done.exception()  # retrieved: a job nobody waits for any more logs nothing

    def _settled(self, key: tuple[str, int], done: asyncio.Future[bytes]) -> None:
        self._pending.pop(key, None)
        if not done.cancelled():
            done.exception()

    # -- the jobs, each in a reader thread --

    def _load(self, station: str, run_id: int) -> ReadRun:
        """The run read (or kept from before, its files unchanged)."""
        located = self.locator.locate(station, run_id)
        signature = located.signature()
        kept = self.cache.get((station, run_id), signature)
        if kept is not None:
            return kept
        try:
            run = self._read(located.files, run_id)
        except (InputError, OSError) as err:
            if located.writing and located.stored is None:  # its samples not flushed yet
                raise RunRequestError(
                    404,
                    f"run {run_id} of {station}: the recorder is still writing its file, which "
                    f"holds none of its samples yet ({_text(err)})",
                    pending=True,
                ) from err
            raise RunRequestError(422, f"run {run_id} of {station}: {_text(err)}") from err
        document = run_document(run) | self._found(located)
        read = ReadRun(
            signature, gzipped_json(document), overlay_run_of(run, f"{station}/{run_id}"),
            located.stored,
        )  # fmt: skip
        self.cache.put((station, run_id), read)
        return read

    def _found(self, located: LocatedRun) -> dict[str, Any]:
        """What the page says beside the recording's data: where it was found, the store's
        row, the downloads, the outside viewers."""
        stored = located.stored
        return {
            "key": f"{located.station}/{located.run_id}",
            "found": {
                "recording": None if stored is None else stored.recording,
                "recording_host": None if stored is None else stored.recording_host,
                "note": located.note,
                "writing": located.writing,
            },
            "stored": None if stored is None else as_dict(stored),
            "downloads": downloads(located),
            "viewers": self.viewers,
        }

    def _part(self, station: str, run_id: int, alignment: Alignment) -> bytes:
        base = self._load(station, run_id)
        part_id = base.part_id
        if part_id is None:
            raise RunRequestError(404, f"run {run_id} of {station} names no part: no part's runs")
        rows, left_out = self.locator.part_runs(part_id, PART_RUNS)
        key = f"{station}/{run_id}"
        keyed = [
            (f"{r.result.station}/{r.result.run_id}", r.result.station, r.result.run_id)
            for r in rows
        ]
        runs = self._curves(keyed, key, base, left_out)
        if key not in dict(runs):
            runs.insert(0, (key, base.curves))  # the store has not got its row yet
        document = self._aligned(lambda: part_overlay_document(runs, key, alignment))
        with_spindles(document, [run for _, run in runs])
        return gzipped_json(
            document | {"part_id": part_id, "total": len(rows), "left_out": left_out}
        )

    def _band(self, station: str, run_id: int, count: int, alignment: Alignment) -> bytes:
        base = self._load(station, run_id)
        result = base.stored.result if base.stored is not None else base.curves.result
        if result is None:
            raise RunRequestError(404, f"run {run_id} of {station} has no result: no program")
        try:
            rows = self.locator.program_runs(station, result.program_id, result.time_ns, count)
        except StoreError as err:
            raise RunRequestError(503, f"the results store did not answer: {err}") from err
        left_out: list[str] = []
        keyed = [(f"{station}/{r.result.run_id}", station, r.result.run_id) for r in rows]
        key = f"{station}/{run_id}"
        others = self._curves(keyed, key, base, left_out)
        document = self._aligned(
            lambda: program_band_document((key, base.curves), others, alignment)
        )
        program = {"id": result.program_id, "name": result.program_name}
        notes = left_out + [f"{n['key']}: {n['note']}" for n in document.pop("left_out")]
        return gzipped_json(document | {"program": program, "asked": count, "left_out": notes})

    def _cycle(self, station: str, run_id: int, alignment: Alignment) -> bytes:
        base = self._load(station, run_id)
        result = base.stored.result if base.stored is not None else base.curves.result
        if result is None or result.sync_id is None:
            raise RunRequestError(
                404,
                f"run {run_id} of {station} is not a spindle's run of a multi-spindle cycle: "
                "no cycle to overlay",
            )
        files, stored = base.curves.files, base.stored
        return gzipped_json(
            self._aligned(lambda: cycle_document(station, run_id, files, stored, alignment))
        )

    def _curves(
        self, keyed: list[tuple[str, str, int]], key: str, base: ReadRun, left_out: list[str]
    ) -> list[tuple[str, OverlayRun]]:
        """The curves of ``keyed`` (key, station, run), those that cannot be read named in
        ``left_out``."""
        runs = []
        for other_key, station, run_id in keyed:
            if other_key == key:
                runs.append((key, base.curves))
                continue
            try:
                runs.append((other_key, self._load(station, run_id).curves))
            except RunRequestError as err:
                left_out.append(err.text)
        return runs

    @staticmethod
    def _aligned(make: Callable[[], dict[str, Any]]) -> dict[str, Any]:
        try:
            return make()
        except InputError as err:
            raise RunRequestError(422, str(err)) from err


def _text(err: BaseException) -> str:
    if isinstance(err, OSError) and err.strerror:
        return f"{err.filename}: {err.strerror}" if err.filename else err.strerror
    return str(err)
