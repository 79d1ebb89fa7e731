"""Run files as the recorder leaves them, written some days ago, for the retention tests:
a real MCAP (its samples, the run's result or none) named by :func:`file_path`, an
``.rrd`` beside it, both last written at a chosen time; and results put in a real store.

No product code imports it.
"""

from __future__ import annotations

import os
import time
from collections.abc import Iterable
from pathlib import Path

from shared.contract import TighteningResult, encode
from shared.recordings import classify, file_path, rerun_path
from shared.recordings.mcap import McapSink
from shared.results import ResultsStore, StoreTarget, stored_result
from tests.support import factories

DAY_NS = 86_400 * 1_000_000_000


def run_result(run_id: int, verdict: str = "OK", station: str = "st1") -> TighteningResult:
    """Run ``run_id``'s result, OK or NOK."""
    reasons = "" if verdict == "OK" else "torque above its window"
    return factories.result(run_id, station=station, result=verdict, nok_reasons=reasons)


def write_run_file(
    folder: Path,
    run_id: int | None,
    written_ns: int,
    results: Iterable[TighteningResult] = (),
    station: str = "st1",
    samples: int = 20,
    rerun_bytes: int = 4096,
    part: int = 1,
) -> Path:
    """A run file of ``station`` opened and last written at ``written_ns`` (``run_id`` None:
    an idle file; ``part``: its part) holding ``samples`` samples and ``results``, with an
    ``.rrd`` of ``rerun_bytes`` beside it (0: none); its path."""
    path = file_path(folder, station, run_id, written_ns, part)
    metadata = {"station": {"station": station}}
    with McapSink(path, metadata, run_id, written_ns, fsync=False) as sink:
        for n in range(samples if run_id is not None else 0):
            sample = factories.sample(run_id or 0, n, station=station)
            sink.write(classify(f"boltwatch/{station}/samples", encode(sample), written_ns))
        for result in results:
            sink.write(classify(f"boltwatch/{station}/results", encode(result), written_ns))
    touched = [path]
    if rerun_bytes:
        rerun = rerun_path(path)
        rerun.write_bytes(os.urandom(rerun_bytes))  # incompressible: it takes its size on disk
        touched.append(rerun)
    for written in touched:
        os.utime(written, ns=(written_ns, written_ns))
    return path


def store(target: StoreTarget, results: Iterable[TighteningResult], recording: Path) -> None:
    """Put ``results`` into the store at ``target`` (made if missing), in ``recording``, as
    stored now (a recorder starting next reads no older recording to catch up)."""
    now_ns = time.time_ns()
    with ResultsStore(target) as opened:
        opened.add(
            [stored_result(r, "", str(recording.resolve()), "host", now_ns) for r in results]
        )
