"""One run's Rerun recording: an ``.rrd`` beside the run's MCAP, written in column batches.

Each run file borrows one of its station's :class:`rerun.RecordingStream`
(application ``boltwatch``, recording id ``<station>``; why streams are
pooled: :mod:`shared.recordings.rerun.rerun_streams`) and points it at its own
``<same stem>.rrd``, with the layout once per folder in ``boltwatch.rbl``; with live viewing on it
also streams to the process's gRPC server (:class:`RerunLive`). Samples are
buffered in plain lists and sent with ``send_columns`` every
``batch_samples`` samples, at each flush tick and at close: nothing per
sample but a few list appends. Writing files only, a batch is what a flush
tick gathers (:data:`FILE_BATCH_SAMPLES` is more than a second of samples):
each ``send_columns`` costs Rerun a fixed price, and 250-sample batches made
Rerun's share of the recorder's CPU 7 µs a sample; with a live viewer, every
:data:`LIVE_BATCH_SAMPLES` (0.25 s behind the tool). Events, predictions, the stop decision (a
replayed one is marked so), the run summary and a controller's result are
rare and go out at flush ticks (one chunk per entity and tick: each Rerun
chunk costs about a kilobyte of schema on disk).

MCAP is the record that matters: every Rerun call here is guarded. The first
failure is logged with its traceback, the sink disables itself and the
recorder goes on (:attr:`RerunSink.failed`). Entity paths and the layout are
in :mod:`shared.recordings.rerun.rerun_blueprint`.
"""

from __future__ import annotations

import logging
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any
from urllib.parse import quote

import numpy as np
import rerun as rr

from shared.recordings.layout import rerun_path
from shared.recordings.received import Received
from shared.recordings.rerun import rerun_blueprint as bp
from shared.recordings.rerun.rerun_streams import borrow_stream, ensure_layout_file, return_stream
from shared.contract import channels
from shared.contract import RunClock

LOG = logging.getLogger(__name__)

DEFAULT_GRPC_PORT = 9876
#: samples per column batch writing files only: more than a flush tick (1 s) gathers
FILE_BATCH_SAMPLES = 2000
#: samples per column batch with a live viewer: 0.25 s at 1 kHz
LIVE_BATCH_SAMPLES = 250
#: the longest a closing sink waits for Rerun to write what it was sent (milliseconds for a
#: run's file): the recorder's shutdown never waits on Rerun for ever; past it the .rrd
#: is said to have failed and the MCAP of the run stands
CLOSE_FLUSH_TIMEOUT_S = 10.0


@dataclass(frozen=True, slots=True)
class RerunOptions:
    """How runs go to Rerun: a ``.rrd`` beside each MCAP file, and/or a live gRPC server."""

    batch_samples: int = FILE_BATCH_SAMPLES  # samples sent every this many, and at flushes
    live_url: str | None = None
    write_files: bool = True  # False: live only (``--no-rerun --rerun-serve``)


class _Series:
    """A buffered scalar series: (time_ns, value) pairs, sent as one column batch."""

    __slots__ = ("path", "times_ns", "values")

    def __init__(self, path: str) -> None:
        self.path = path
        self.times_ns: list[int] = []
        self.values: list[float] = []

    def add(self, time_ns: int, value: float | None) -> None:
        if value is not None:
            self.times_ns.append(time_ns)
            self.values.append(value)

    def send(self, stream: rr.RecordingStream, indexes: _TimeIndexes) -> int:
        count = len(self.values)
        if count == 0:
            return 0
        stream.send_columns(
            self.path,
            indexes=indexes.of(self.times_ns),
            columns=rr.Scalars.columns(scalars=np.asarray(self.values, dtype=np.float64)),
        )
        self.times_ns.clear()
        self.values.clear()
        return count


class _TimeIndexes:
    """The time columns of one send, built once per distinct list of times: torque and
    angle share theirs, and so do an event's figures (building one costs Rerun as much
    as sending it)."""

    __slots__ = ("_built", "_run_started_ns")

    def __init__(self, run_started_ns: int) -> None:
        self._run_started_ns = run_started_ns
        self._built: list[tuple[list[int], list[rr.TimeColumn]]] = []

    def of(self, times_ns: list[int]) -> list[rr.TimeColumn]:
        for times, columns in self._built:
            if times == times_ns:
                return columns
        columns = time_columns(times_ns, self._run_started_ns)
        self._built.append((list(times_ns), columns))  # the series clears its own list
        return columns


class RerunSink:
    """Write one run's messages to ``path`` (an ``.rrd``) and, optionally, a live server."""

    def __init__(
        self,
        path: Path,
        station: str,
        run_id: int,
        run_started_ns: int,
        options: RerunOptions = RerunOptions(),  # frozen: shared safely
        recording_name: str | None = None,  # default: the file's stem
    ) -> None:
        self.path = path
        self.run_id = run_id
        self.samples = 0  # samples sent to Rerun so far
        self.failed = False
        self._run_started_ns = run_started_ns
        self._clock = RunClock(run_started_ns)
        self._batch_samples = max(1, options.batch_samples)
        self._pending_samples = 0
        self._closed = False
        self._text_times_ns: list[int] = []
        self._texts: list[str] = []
        self._levels: list[str] = []
        names = [bp.TORQUE, bp.ANGLE, bp.FORCE, bp.PEAKS, bp.PLATEAUS, bp.PREDICTED_PEAKS]
        names += [bp.PREDICTED_PLATEAUS, bp.TORQUE_STOP, bp.TORQUE_STAGE, bp.FORCE_STOP, bp.F_SS]
        names += list(bp.K_PATHS)
        names += [bp.EVENT_INTENSITY, bp.PROCESS_INTENSITY]
        self._series = {name: _Series(name) for name in names}
        self._torque = self._series[bp.TORQUE]
        self._angle = self._series[bp.ANGLE]
        self._force = self._series[bp.FORCE]
        sinks: list[Any] = []
        if options.write_files:
            path.parent.mkdir(parents=True, exist_ok=True)
            ensure_layout_file(path.parent)
            sinks.append(rr.FileSink(path))
        self._station = station
        self._stream = borrow_stream(station)
        if options.live_url is not None:
            sinks.append(rr.GrpcSink(options.live_url))
        try:
            self._stream.set_sinks(*sinks)
        except Exception:
            self._stream.disconnect()  # drop the buffered sink, not "dropping data" at exit
            raise
        self._stream.send_recording_name(recording_name or path.stem)
        self._stream.send_recording_start_time_nanos(run_started_ns)
        bp.log_series_styles(self._stream)

    def write(self, received: Received) -> None:
        """Buffer one decoded message; send a batch when ``batch_samples`` are waiting."""
        message = received.message
        if self.failed or message is None:
            return
        try:
            if received.schema_name == channels.SAMPLES.schema_name:
                self._add_samples([message])
            elif received.schema_name == channels.EVENTS.schema_name:
                self._event(message)
            elif received.schema_name == channels.DECISION.schema_name:
                self._decision(message)
            elif received.schema_name == channels.STAGE.schema_name:
                self._stage(message)
            elif received.schema_name == channels.RUNS.schema_name:
                self._summary(message)
            elif received.schema_name == channels.CONTROLLER.schema_name:
                self._controller(message)
            elif received.schema_name == channels.TOOL.schema_name:
                self._text(
                    message.time_ns,
                    f"tool {message.state} (tool {message.tool_id}, program {message.program_id})",
                    "INFO",
                )
        except Exception:
            self._fail("write")

    def write_samples(self, samples: Sequence[Received]) -> None:
        """Buffer decoded Samples (a batch's); send a batch when ``batch_samples`` are waiting."""
        if self.failed:
            return
        try:
            self._add_samples([received.message for received in samples])
        except Exception:
            self._fail("write")

    def _add_samples(self, samples: list[Any]) -> None:
        times_ns = [sample.time_ns for sample in samples]
        self._torque.times_ns += times_ns
        self._torque.values += [sample.torque_nm for sample in samples]
        self._angle.times_ns += times_ns
        self._angle.values += [sample.angle_deg for sample in samples]
        force = self._force
        for sample in samples:
            force.add(sample.time_ns, sample.force_n)
        self._pending_samples += len(samples)
        if self._pending_samples >= self._batch_samples:
            self._send_samples()

    def flush(self) -> None:
        """Send everything buffered (the recorder's flush tick)."""
        if self.failed or self._closed:
            return
        try:
            self._send()
            self._stream.flush(timeout_sec=0.0)  # start writing; never wait in the recorder
        except Exception:
            self._fail("flush")

    def close(self) -> None:
        """Send what is left, finish the file (footer) and drop the stream; safe twice."""
        if self._closed:
            return
        self._closed = True
        try:
            if not self.failed:
                self._send()
                self._stream.flush(timeout_sec=CLOSE_FLUSH_TIMEOUT_S)  # raises past it
            self._stream.disconnect()  # finishes the file
        except Exception:
            self._fail("close")
        if not self.failed:
            return_stream(self._station, self._stream)
        LOG.info("closed %s: %d samples%s", self.path, self.samples, " (FAILED)" * self.failed)

    def _event(self, event: Any) -> None:
        clock = self._clock
        t_ns = clock.ns(event.time_s)
        series = self._series
        series[bp.PEAKS].add(t_ns, event.peak_torque_nm)
        series[bp.PLATEAUS].add(t_ns, event.plateau_force_n)
        series[bp.F_SS].add(t_ns, event.f_ss_hz)
        for path, value in zip(bp.K_PATHS, (event.k1, event.k2, event.k3), strict=True):
            series[path].add(t_ns, value)
        series[bp.EVENT_INTENSITY].add(t_ns, event.intensity)
        series[bp.PROCESS_INTENSITY].add(t_ns, event.process_intensity)
        for prediction in event.predictions:
            p_ns = clock.ns(prediction.time_s)
            series[bp.PREDICTED_PEAKS].add(p_ns, prediction.peak_torque_nm)
            series[bp.PREDICTED_PLATEAUS].add(p_ns, prediction.plateau_force_n)

    def _decision(self, decision: Any) -> None:
        t_ns = self._clock.ns(decision.time_s)
        self._series[bp.TORQUE_STOP].add(t_ns, decision.torque_nm)
        self._series[bp.FORCE_STOP].add(t_ns, decision.force_n)
        stop = "STOP (replayed, not acted on)" if decision.advisory else "STOP"
        text = (
            f"{stop} {decision.reason} at {decision.time_s:.3f} s: torque {decision.torque_nm:.1f} "
            f"N·m, force {_n(decision.force_n)}, predicted "
            + (
                f"torque {decision.predicted_torque_nm:.4g} N·m"
                if decision.predicted_torque_nm is not None
                else f"force {_n(decision.predicted_force_n)}"
            )
        )
        self._text(t_ns, text + (f" ({decision.detail})" if decision.detail else ""), "WARN")

    def _stage(self, stage: Any) -> None:
        t_ns = self._clock.ns(stage.time_s)
        self._series[bp.TORQUE_STAGE].add(t_ns, stage.torque_nm)
        pulse = f" {stage.pulse}" if stage.command in ("pulse", "stop") else ""
        text = (
            f"final stage: {stage.command}{pulse} ({stage.reason}) at {stage.time_s:.3f} s, "
            f"torque {stage.torque_nm:.1f} N·m"
        )
        self._text(t_ns, text + (f" ({stage.detail})" if stage.detail else ""), "INFO")

    def _summary(self, summary: Any) -> None:
        text = (
            f"run {summary.run_id} {summary.tool_state}: {summary.events} events, "
            f"stop {summary.stop_reason or 'by the tool'}, reached {_n(summary.reached_force_n)} "
            f"/ target {_n(summary.target_force_n)}, torque {summary.reached_torque_nm:.1f} N·m, "
            f"error {'-' if summary.error_pct is None else f'{summary.error_pct:.2f}'} %, "
            f"I_process {summary.process_intensity:.3g}, {summary.samples} samples"
        )
        self._text(summary.ended_ns, text, "INFO")

    def _controller(self, result: Any) -> None:
        steps = ", ".join(f"{step.name} {step.result or '?'}" for step in result.steps)
        text = (
            f"controller: {result.result or '?'} (quality code {result.quality_code or '-'}, "
            f"part {result.part_id or '-'}); steps: {steps}"
        )
        self._text(result.time_ns, text, "INFO" if result.result == "OK" else "WARN")

    def _text(self, time_ns: int, text: str, level: str) -> None:
        self._text_times_ns.append(time_ns)
        self._texts.append(text)
        self._levels.append(level)

    def _send_samples(self, indexes: _TimeIndexes | None = None) -> None:
        indexes = indexes or _TimeIndexes(self._run_started_ns)
        self.samples += self._torque.send(self._stream, indexes)
        self._angle.send(self._stream, indexes)
        self._force.send(self._stream, indexes)
        self._pending_samples = 0

    def _send(self) -> None:
        """Samples and every rare series (one chunk per entity and flush, not per event)."""
        indexes = _TimeIndexes(self._run_started_ns)
        self._send_samples(indexes)
        for series in self._series.values():
            series.send(self._stream, indexes)
        if self._texts:
            self._send_texts(self._text_times_ns, self._texts, self._levels)
            self._text_times_ns, self._texts, self._levels = [], [], []

    def _send_texts(self, times_ns: Sequence[int], texts: list[str], levels: list[str]) -> None:
        self._stream.send_columns(
            bp.LOG,
            indexes=time_columns(times_ns, self._run_started_ns),
            columns=rr.TextLog.columns(text=texts, level=levels),
        )

    def _fail(self, what: str) -> None:
        if not self.failed:
            LOG.exception(
                "Rerun %s failed for %s; its .rrd ends here, MCAP goes on", what, self.path
            )
        self.failed = True

    def __enter__(self) -> RerunSink:
        return self

    def __exit__(self, *_exc: object) -> None:
        self.close()


def open_rerun_sink(
    mcap_path: Path, station: str, run_id: int, run_started_ns: int, options: RerunOptions
) -> RerunSink | None:
    """The run's sink beside ``mcap_path`` (same stem, ``.rrd``); None, logged, if it fails."""
    path = rerun_path(mcap_path)
    try:
        return RerunSink(path, station, run_id, run_started_ns, options)
    except Exception:
        LOG.exception("cannot open Rerun recording %s; recording MCAP only", path)
        return None


class RerunLive:
    """The process's live view: a Rerun gRPC server (and optionally the wheel's web viewer).

    The server is hosted by a stream that logs nothing; every run's stream
    connects to it as a client (:attr:`RerunOptions.live_url`), so one viewer
    sees every run and station as separate recordings.
    """

    def __init__(self, grpc_port: int = DEFAULT_GRPC_PORT, web_port: int | None = None) -> None:
        self._hub = rr.RecordingStream(
            bp.APPLICATION_ID, recording_id="boltwatch-live", send_properties=False
        )
        self.url = self._hub.serve_grpc(grpc_port=grpc_port, default_blueprint=bp.run_blueprint())
        self.web_url: str | None = None
        LOG.info("Rerun live view: rerun %s", self.url)
        if web_port is not None:
            rr.serve_web_viewer(web_port=web_port, open_browser=False, connect_to=self.url)
            self.web_url = f"http://127.0.0.1:{web_port}/?url={quote(self.url, safe='')}"
            LOG.info("Rerun web viewer: %s", self.web_url)

    def close(self) -> None:
        """Shut the gRPC server down; safe to call twice."""
        self._hub.disconnect()


def time_columns(times_ns: Sequence[int], run_started_ns: int) -> list[rr.TimeColumn]:
    """``run_time`` (duration since run start) and ``log_time`` of integer-ns times."""
    times = np.asarray(times_ns, dtype=np.int64)
    return [
        rr.TimeColumn(bp.RUN_TIME, duration=(times - run_started_ns).view("timedelta64[ns]")),
        rr.TimeColumn(bp.LOG_TIME, timestamp=times.view("datetime64[ns]")),
    ]


def _n(force_n: float | None) -> str:
    return "-" if force_n is None else f"{force_n:.0f} N"
