"""A recordings folder of good run files and the hostile ones a reader must get past.

Real files, written by the recorder's own sink: a file cut to 10 bytes, an
empty one, a FIFO named like a run file, a file whose typed ``results``
channel holds a payload that is no result (what a recorder of ours would
have kept raw: a file written by something else), and results whose
figures are absurd (±1e308 Nm).
"""

from __future__ import annotations

import os
from pathlib import Path

from shared.contract import JudgedFigure, TighteningResult, channels, encode
from shared.recordings import Received, classify, file_path
from shared.recordings.mcap import McapSink
from tests.support import factories

#: when the good runs ended (UTC 2026-03-02 08:00)
DAY_NS = 1_772_438_400_000_000_000
GOOD_RUNS = 12
#: what the hostile payloads are: a Sample where a result belongs, {}, binary, a NaN torque
WRONG_PAYLOADS = {
    "sample": encode(factories.sample(1, 0)),
    "empty object": b"{}",
    "binary": bytes(range(256)),
    "nan": encode(factories.result(1)).replace(b'"value":190.0', b'"value":NaN'),
}


def good_result(run_id: int) -> TighteningResult:
    """Run ``run_id``'s result: torque 190 + run id Nm, in program 1's window."""
    torque = JudgedFigure(190.0 + run_id, 180.0, 240.0, "ok")
    return factories.result(run_id, time_ns=DAY_NS + run_id * 10**9, final_torque_nm=torque)


def write_result_file(folder: Path, result: TighteningResult) -> Path:
    """A run file of station st1 holding ``result`` (as the recorder writes it)."""
    path = file_path(folder, result.station, result.run_id, result.time_ns)
    with McapSink(path, {"station": {"station": "st1"}}, result.run_id, result.time_ns) as sink:
        sink.write(classify("boltwatch/st1/results", encode(result), result.time_ns))
    return path


def write_payload_file(folder: Path, run_id: int, payloads: list[bytes]) -> Path:
    """A run file whose typed ``results`` channel holds ``payloads`` as they are."""
    time_ns = DAY_NS + run_id * 10**9
    path = file_path(folder, "st1", run_id, time_ns)
    key = "boltwatch/st1/results"
    with McapSink(path, {"station": {"station": "st1"}}, run_id, time_ns) as sink:
        for payload in payloads:  # a decoded message stands in: the payload goes as it is
            received = Received(key, "st1", channels.RESULTS.schema_name, object(), payload, 0, 0)
            sink.write(received._replace(log_time_ns=time_ns, publish_time_ns=time_ns))
    return path


def good_folder(folder: Path) -> list[Path]:
    """:data:`GOOD_RUNS` run files, one good result each (runs 1 to 12)."""
    return [write_result_file(folder, good_result(n)) for n in range(1, GOOD_RUNS + 1)]


def cut(path: Path, keep_bytes: int) -> Path:
    """``path`` cut to its first ``keep_bytes`` bytes (0: empty)."""
    path.write_bytes(path.read_bytes()[:keep_bytes])
    return path


def fifo_beside(path: Path, run_id: int) -> Path:
    """A FIFO named like run ``run_id``'s file, in the day folder of ``path``."""
    fifo = path.with_name(f"st1_run{run_id}_080000.mcap")
    os.mkfifo(fifo)
    return fifo
