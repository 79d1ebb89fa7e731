"""Two spools of one station: its acquisition's (which starts the runs) and a line predictor's.

The recorder's filing without zenoh (:class:`SpoolFiling` on a :class:`Recorder`):
the acquisition's messages are filed in order, each run in one file; the
predictor's, which start no run, are filed as they first come and never take
the acquisition's run file away (a gap in the predictor's numbers opens no
hole). One sent again goes into the file of its run while that is open, else
into a file of that run of its own, finished once idle; one that comes twice is
filed once.
"""

from __future__ import annotations

import json
from collections import Counter
from pathlib import Path
from typing import Any

from mcap.reader import make_reader

from services.recorder.live.recorder import LATE_FILES_IDLE_NS, Recorder
from services.recorder.live.run_files import StationFiles
from services.recorder.live.spool_filing import SpoolFiling
from services.recorder.live.spool_keeper import SpoolKeeper
from services.recorder.served_stations import limits_of
from shared.config import LoadedStation
from shared.contract import SeqMark, ToolState, channels, encode
from shared.recordings import FileMetadata, Received, classify
from tests.support import factories

S = factories.S
MS = factories.MS
T0 = factories.T0


class Line:
    """The recorder's filing of st1, fed message by message."""

    def __init__(self, station: LoadedStation) -> None:
        self.recorder = Recorder(
            station.recordings_folder, limits_of(station), FileMetadata(station)
        )

        def file(received: Received, _filed_ns: int, files: StationFiles | None) -> None:
            self.recorder.write(received, files)

        self.filing = SpoolFiling(SpoolKeeper(station.recordings_folder), self.recorder, file)
        self.seqs: Counter[str] = Counter()

    def put(self, source: str, message: Any, at_ns: int) -> int:
        """``message`` put live by ``source``: its number."""
        self.seqs[source] += 1
        self.put_as(source, self.seqs[source], message, at_ns)
        return self.seqs[source]

    def put_as(
        self, source: str, seq: int, message: Any, at_ns: int, kept_before: int | None = None
    ) -> None:
        """Message ``seq`` of ``source`` (``kept_before``: sent again)."""
        key = channels.of_message(message).key("st1")
        received = classify(key, encode(message), at_ns)
        self.filing.file(received, SeqMark(source, 1, seq, kept_before), at_ns)

    def run(self, run_id: int, at_ns: int, samples: int = 20, end: bool = True) -> None:
        """The acquisition's messages of one run (``end``: with its ``done``)."""
        self.put("acquisition", ToolState("st1", run_id, 7, 1, "running", at_ns), at_ns)
        self.samples(run_id, at_ns, range(samples))
        if end:
            self.end(run_id, at_ns + samples * MS)

    def samples(self, run_id: int, at_ns: int, sequences: range) -> None:
        for n in sequences:
            sample = factories.sample(run_id, n, time_ns=at_ns + n * MS)
            self.put("acquisition", sample, at_ns + n * MS)

    def end(self, run_id: int, at_ns: int) -> None:
        self.put("acquisition", ToolState("st1", run_id, 7, 1, "done", at_ns), at_ns)


def read(folder: Path) -> dict[str, list[tuple[str, dict[str, Any]]]]:
    """(topic, message) of every file of st1, by file name."""
    files = {}
    for path in sorted(folder.glob("st1/*/*.mcap")):
        with path.open("rb") as handle:
            files[path.name] = [
                (channel.topic.split("/", 2)[2], json.loads(message.data))
                for _schema, channel, message in make_reader(handle).iter_messages()
            ]
    return files


def test_a_line_predictors_spool_never_splits_a_run_and_files_each_message_once(
    station: LoadedStation,
) -> None:
    line = Line(station)
    event_1 = factories.event(1, 1, time_ns=T0 + 5 * MS)
    result_1 = factories.result(1, time_ns=T0 + 20 * MS)
    event_2 = factories.event(1, 3, time_ns=T0 + 7 * MS)
    line.run(1, T0, samples=5, end=False)  # the acquisition's run 1 ...
    line.put("predictor", event_1, T0 + 5 * MS)
    line.seqs["predictor"] += 1  # ... the predictor's next message never came live
    lost = line.seqs["predictor"]
    line.put("predictor", event_2, T0 + 7 * MS)  # a gap in the predictor's numbers
    line.samples(1, T0, range(5, 10))
    line.end(1, T0 + 10 * MS)
    line.put("predictor", result_1, T0 + 30 * MS)
    line.run(2, T0 + S)
    line.run(3, T0 + 10 * S)  # run 1's file is finished by now
    event_3 = factories.event(3, 1, time_ns=T0 + 10 * S + 5 * MS)
    line.put("predictor", event_3, T0 + 10 * S + 5 * MS)
    # the predictor's spool sends again what the recorder lacks (twice: an ack was lost)
    missing = factories.event(1, 2, time_ns=T0 + 6 * MS)
    for again_ns in (T0 + 11 * S, T0 + 12 * S):
        line.put_as("predictor", lost, missing, again_ns, kept_before=lost - 1)
    event_3_again = line.seqs["predictor"]
    line.put_as("predictor", event_3_again, event_3, T0 + 12 * S, kept_before=lost)
    line.recorder.tick(T0 + 13 * S)
    line.recorder.tick(T0 + 13 * S + LATE_FILES_IDLE_NS)  # the late file, idle, is finished
    late_open = [p for p in line.recorder.open_paths() if "_run1_" in p.name]
    line.recorder.close()
    files = read(station.recordings_folder)

    runs = {
        run_id: [name for name, messages in files.items() if any(
            topic in ("tool", "samples") and m["run_id"] == run_id for topic, m in messages
        )]
        for run_id in (1, 2, 3)
    }  # fmt: skip
    assert all(len(names) == 1 for names in runs.values()), runs  # each run whole in one file
    assert late_open == []
    (run_1,) = runs[1]
    assert [t for t, m in files[run_1] if t == "tool"] == ["tool", "tool"]
    assert ("events", json.loads(encode(event_1))) in files[run_1]
    assert ("events", json.loads(encode(event_2))) in files[run_1]
    assert ("results", json.loads(encode(result_1))) in files[run_1]
    (run_3,) = runs[3]
    assert [m for t, m in files[run_3] if t == "events"] == [json.loads(encode(event_3))]
    sent_again = [
        (name, topic)
        for name, messages in files.items()
        for topic, m in messages
        if m == json.loads(encode(missing))
    ]
    assert len(sent_again) == 1, sent_again  # once, though it came twice
    ((name, _),) = sent_again
    assert "_run1_" in name and name != run_1  # its run's own file: run 1's was finished
