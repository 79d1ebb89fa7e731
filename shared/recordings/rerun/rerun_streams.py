"""Rerun streams that outlive runs: a pool per station, and the layout file per folder.

One :class:`rerun.RecordingStream` per run would be simplest, but rerun-sdk
0.41 keeps about a megabyte of every stream it drops, blueprint streams
included (measured: 1.5 MiB per 1700-sample run, about 2 GB an hour for one
station; upstream rerun-io/rerun#12623), while a stream whose sinks are
switched from file to file does not grow. So a run borrows an idle stream of
its station (a new one only when every stream of the station is busy, e.g.
while the previous run's file is still open for late messages), points it at
its own ``.rrd`` and gives it back when the file is finished. A stream whose
run failed is never given back: whatever it still buffers must not end up in
the next run's file.

Each stream is one Rerun recording (``boltwatch`` / ``<station>``, or
``<station>-2`` ... for the extra ones) and each ``.rrd`` one run of it, named
by its recording name. Open runs one at a time (two runs of one station share
a recording id and would merge in the viewer), or compare runs in the MCAP
tools.

The layout is a file of its own, ``boltwatch.rbl`` once per folder, because
sending a blueprint creates a stream too. Open a run with its layout:
``rerun RUN.rrd boltwatch.rbl``.
"""

from __future__ import annotations

from pathlib import Path

import rerun as rr

from shared.recordings.rerun import rerun_blueprint as bp

BLUEPRINT_FILE = "boltwatch.rbl"

_idle: dict[str, list[rr.RecordingStream]] = {}
_created: dict[str, int] = {}
_folders_with_layout: set[Path] = set()


def borrow_stream(station: str) -> rr.RecordingStream:
    """An idle stream of ``station``'s, or a new one; give it back with :func:`return_stream`."""
    idle = _idle.setdefault(station, [])
    if idle:
        return idle.pop()
    count = _created[station] = _created.get(station, 0) + 1
    recording_id = station if count == 1 else f"{station}-{count}"
    return rr.RecordingStream(bp.APPLICATION_ID, recording_id=recording_id, send_properties=True)


def return_stream(station: str, stream: rr.RecordingStream) -> None:
    """``stream`` (disconnected, nothing buffered) may serve the station's next run."""
    _idle.setdefault(station, []).append(stream)


def ensure_layout_file(folder: Path) -> Path:
    """``<folder>/boltwatch.rbl``, the layout of every run in the folder, written once."""
    path = folder / BLUEPRINT_FILE
    if folder not in _folders_with_layout:
        if not path.exists():
            bp.run_blueprint().save(bp.APPLICATION_ID, str(path))
        _folders_with_layout.add(folder)
    return path
