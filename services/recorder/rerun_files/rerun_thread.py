"""The one thread that makes every Rerun call of the process, so the recorder's never does.

Opening a run's ``.rrd`` (a file sink, a pooled stream, the series styles),
sending its column batches and finishing it (a last send, a flush, the
disconnect that writes the footer) cost milliseconds each; on a line of 50
stations with a run starting every 25 ms that was most of the recorder's
work thread (README, Benchmarks: the line server). A :class:`RerunSink`
therefore only buffers on the caller's thread and hands everything that
touches Rerun to :data:`RERUN_THREAD` as a job. One thread for all sinks:
jobs run in the order they were given, so a run's stream is opened before
its batches are sent and finished after them, and the station stream pool
(:mod:`.rerun_streams`) is used by this thread alone.

Nothing is dropped: when :data:`MAX_JOBS` jobs wait, :meth:`RerunThread.submit`
waits for room (back-pressure on the recorder, never lost batches).
:meth:`RerunThread.wait` returns once every job given before it has run
(a sink's ``close()`` uses it, so its ``.rrd`` is whole when it returns).
A job that raises is logged; the thread goes on.
"""

from __future__ import annotations

import atexit
import logging
import queue
import threading
from collections.abc import Callable

LOG = logging.getLogger(__name__)

#: jobs waiting before ``submit`` waits too (a job is one sink's open, batch or close)
MAX_JOBS = 10_000


class RerunThread:
    """A worker thread running submitted jobs one at a time, in order."""

    def __init__(self, name: str = "rerun", max_jobs: int = MAX_JOBS) -> None:
        self._name = name
        self._jobs: queue.Queue[Callable[[], None]] = queue.Queue(max_jobs)
        self._thread: threading.Thread | None = None
        self._start_lock = threading.Lock()

    def submit(self, job: Callable[[], None]) -> None:
        """Run ``job`` on the thread after every job given before it."""
        if self._thread is None:
            self._start()
        self._jobs.put(job)

    def wait(self) -> None:
        """Return once every job submitted before this call has run."""
        if self._thread is None:
            return
        if threading.current_thread() is self._thread:
            raise RuntimeError("RerunThread.wait() called from its own thread")
        done = threading.Event()
        self._jobs.put(done.set)
        done.wait()

    def _start(self) -> None:
        with self._start_lock:
            if self._thread is None:
                # a daemon, so a job never holds up the interpreter's exit; atexit waits
                # for the jobs already given (a sink's footer), then the thread is left
                thread = threading.Thread(target=self._run, name=self._name, daemon=True)
                thread.start()
                self._thread = thread
                atexit.register(self.wait)

    def _run(self) -> None:
        while True:
            job = self._jobs.get()
            try:
                job()
            except Exception:  # a sink's own failures are caught in the sink: this is a bug
                LOG.exception("a Rerun job failed")


#: the process's Rerun thread, used by every :class:`.rerun_sink.RerunSink`
RERUN_THREAD = RerunThread()
