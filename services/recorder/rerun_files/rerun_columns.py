"""Buffered scalar series and the column batches a :class:`.rerun_sink.RerunSink` sends.

The recorder's thread appends to a :class:`Series` and takes what it holds
(:meth:`Series.take`, a :data:`Batch`); the Rerun thread sends the batch
(:func:`send_batch`: one ``send_columns``, one chunk, with ``run_time`` and
``log_time`` indexes from :func:`time_columns`).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import rerun as rr

from services.recorder.rerun_files import rerun_blueprint as bp

#: one series' taken batch: (entity path, times ns, values)
Batch = tuple[str, list[int], list[float]]
#: taken text log lines: (times ns, texts, levels)
Texts = tuple[list[int], list[str], list[str]]


class Series:
    """A buffered scalar series: (time_ns, value) pairs, taken whole and sent as one batch."""

    __slots__ = ("path", "times_ns", "values")

    def __init__(self, path: str) -> None:
        self.path = path
        self.times_ns: list[int] = []
        self.values: list[float] = []

    def add(self, time_ns: int, value: float | None) -> None:
        if value is not None:
            self.times_ns.append(time_ns)
            self.values.append(value)

    def take(self) -> Batch | None:
        """What is buffered (None: nothing), leaving the series empty."""
        if not self.values:
            return None
        batch = (self.path, self.times_ns, self.values)
        self.times_ns, self.values = [], []
        return batch


def send_batch(stream: rr.RecordingStream, batch: Batch, run_started_ns: int) -> int:
    path, times_ns, values = batch
    stream.send_columns(
        path,
        indexes=time_columns(times_ns, run_started_ns),
        columns=rr.Scalars.columns(scalars=np.asarray(values, dtype=np.float64)),
    )
    return len(values)


def time_columns(times_ns: Sequence[int], run_started_ns: int) -> list[rr.TimeColumn]:
    """``run_time`` (duration since run start) and ``log_time`` of integer-ns times."""
    times = np.asarray(times_ns, dtype=np.int64)
    return [
        rr.TimeColumn(bp.RUN_TIME, duration=(times - run_started_ns).view("timedelta64[ns]")),
        rr.TimeColumn(bp.LOG_TIME, timestamp=times.view("datetime64[ns]")),
    ]
