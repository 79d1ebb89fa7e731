"""A run's Rerun recording made from its MCAP file, when somebody wants to look at it.

A line of many stations records MCAP only (``serve recorder --no-rerun``): a
live ``.rrd`` per run costs the recorder about 10 ms of CPU a run (a stream
pointed at a new file, the series styles, a column batch per series and
flush, the file finished), at 50 stations with 1 s runs 40 runs a second and
the largest part of the line recorder's work. ``boltwatch inspect RUN.mcap
--rerun`` makes the run's ``.rrd`` afterwards instead, with the same
:class:`~shared.recordings.rerun.rerun_sink.RerunSink`: every message of
the file, read back in the order it was written and classified as the
recorder classified it when it arrived (its MCAP ``log_time`` is that
arrival), so the file is the one the recorder would have written live.

One difference: a sample outside the contract's sensor range but inside its
station's own (a station file with a wider DBC) was recorded live as a sample
and is left out here, where no station file is read; the MCAP keeps it.
"""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass
from pathlib import Path

from shared.recordings.received import classify
from shared.recordings.mcap import RecordingScan
from shared.recordings.rerun.rerun_sink import RerunOptions, RerunSink
from shared.contract import channels
from shared.errors import InputError


@dataclass(frozen=True, slots=True)
class RrdWritten:
    """What :func:`rrd_from_mcap` wrote."""

    path: Path
    station: str
    run_id: int
    samples: int
    events: int
    scan: RecordingScan  # ``complete`` False: a damaged file, converted as far as it reads


def rrd_from_mcap(mcap_path: Path, target: Path) -> RrdWritten:
    """Write the Rerun recording of the run in ``mcap_path`` to ``target`` (a new ``.rrd``;
    written whole or not at all). InputError when the file holds no run."""
    scan = RecordingScan(mcap_path)
    received = [
        classify(channel.topic, message.data, message.log_time)
        for _schema, channel, message in scan.messages()
    ]
    runs = Counter(r.run_id for r in received if r.message is not None and r.run_id is not None)
    if not runs:
        raise InputError(f"{mcap_path}: no run in this file (an idle file has none)")
    start = next((r for r in received if r.run_started), None)
    run_id: int = runs.most_common(1)[0][0]
    if start is not None and start.run_id is not None:  # the run the file was opened for
        run_id = start.run_id
    first = next(r for r in received if r.run_id == run_id)
    started_ns = start.message.time_ns if start is not None else first.publish_time_ns
    partial = target.with_name(target.name + ".partial")
    partial.unlink(missing_ok=True)
    sink = RerunSink(
        partial, first.station, run_id, started_ns, RerunOptions(), recording_name=mcap_path.stem
    )
    with sink:
        for item in received:
            sink.write(item)
    if sink.failed:
        partial.unlink(missing_ok=True)
        raise InputError(f"{mcap_path}: Rerun failed writing {target} (the log says why)")
    partial.replace(target)
    events = sum(1 for r in received if r.schema_name == channels.EVENTS.schema_name)
    return RrdWritten(target, first.station, run_id, sink.samples, events, scan)
