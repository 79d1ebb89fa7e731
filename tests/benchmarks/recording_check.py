"""Every message of every MCAP file of a recordings folder, checked: for the recording stress.

:func:`check_recordings` reads each ``*.mcap`` file under a folder with the
standard ``mcap`` reader and holds each message to its channel:

- a channel with a schema must carry the schema the contract writes for its
  name (:func:`shared.contract.json_schema`), and each of its messages must
  decode with that type (:func:`shared.contract.decode`: JSON, every field's type
  and bounds) and name the station of its topic;
- a raw channel (no schema: what the recorder refused) is counted as bad,
  message by message: nothing the stress sends is refused;
- each sample's (station, run, sequence) is marked, so that one recorded twice
  is counted (``duplicates``) and the expected ones that are not recorded
  (``missing``, per station, against what each station says it published).

Files the recorder left under their writing name (``.<name>.mcap.writing``)
are counted as ``unfinished``: a recorder stopped cleanly leaves none.
Runs are marked in ``bytearray`` s (one byte a sample), so ten million samples
cost ten megabytes.
"""

from __future__ import annotations

import json
from collections import Counter
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from mcap.reader import make_reader

from shared.contract import BusStats, Sample, channels, decode, json_schema
from shared.errors import InputError
from shared.recordings.layout import WRITING_SUFFIX

#: bad messages kept for the report (the first ones, as they were)
KEPT_BAD = 20


@dataclass
class RecordingCheck:
    """What the files hold, and what is wrong with them."""

    files: int = 0
    unfinished: int = 0
    messages: int = 0
    samples: int = 0
    by_schema: Counter[str] = field(default_factory=Counter)
    bad: int = 0
    bad_examples: list[str] = field(default_factory=list)
    duplicates: int = 0
    unexpected: int = 0  # samples of a run or sequence no station published
    missing: dict[str, int] = field(default_factory=dict)
    seen: dict[tuple[str, int], bytearray] = field(default_factory=dict)
    expected: set[str] = field(default_factory=set)  # the stations whose runs are known
    last_bus: dict[str, BusStats] = field(default_factory=dict)  # the newest of each station

    def bad_message(self, where: str, data: bytes, why: str) -> None:
        self.bad += 1
        if len(self.bad_examples) < KEPT_BAD:
            self.bad_examples.append(f"{where}: {why}: {data[:200]!r} ({len(data)} bytes)")

    @property
    def ok(self) -> bool:
        return not (self.bad or self.duplicates or self.unexpected or self.unfinished)

    def summary(self) -> dict[str, object]:
        return {
            "files": self.files,
            "unfinished_files": self.unfinished,
            "messages": self.messages,
            "samples": self.samples,
            "bad_messages": self.bad,
            "duplicate_samples": self.duplicates,
            "unexpected_samples": self.unexpected,
            "missing_samples": sum(self.missing.values()),
            "missing_by_station": {s: n for s, n in sorted(self.missing.items()) if n},
            "bad_examples": self.bad_examples,
        }


def check_recordings(
    folder: Path, published: Mapping[str, Mapping[int, int]] | None = None
) -> RecordingCheck:
    """Check every file under ``folder``; ``published``: per station, each run's sample
    count (sequences 0..count-1), for what is missing (stations not in it: not counted)."""
    check = RecordingCheck()
    expected_schemas = {
        name: json.dumps(json_schema(kind)).encode() for name, kind in channels.SCHEMA_TYPES.items()
    }
    check.expected = set(published or {})
    for station, runs in (published or {}).items():
        for run_id, count in runs.items():
            check.seen[(station, int(run_id))] = bytearray(count)
    check.unfinished = sum(1 for _ in folder.rglob(f"*{WRITING_SUFFIX}"))
    for path in sorted(folder.rglob("*.mcap")):
        check.files += 1
        _check_file(path, check, expected_schemas)
    for (station, _run_id), marks in check.seen.items():
        if station in check.expected:
            check.missing[station] = check.missing.get(station, 0) + marks.count(0)
    return check


def _check_file(path: Path, check: RecordingCheck, expected_schemas: dict[str, bytes]) -> None:
    with path.open("rb") as handle:
        reader = make_reader(handle)
        for schema, channel, message in reader.iter_messages(log_time_order=False):
            check.messages += 1
            where = f"{path.name} {channel.topic}"
            data = message.data
            if schema is None:
                check.bad_message(where, data, f"raw channel ({channel.metadata})")
                continue
            kind = channels.SCHEMA_TYPES.get(schema.name)
            if kind is None or schema.data != expected_schemas[schema.name]:
                check.bad_message(where, data, f"schema {schema.name!r} is not the contract's")
                continue
            try:
                decoded: Any = decode(kind, data)
            except InputError as err:
                check.bad_message(where, data, f"does not decode as {schema.name}: {err}")
                continue
            station = channel.topic.split("/")[1]
            if getattr(decoded, "station", station) != station:
                check.bad_message(where, data, "names another station than its topic")
                continue
            check.by_schema[schema.name] += 1
            if type(decoded) is Sample:
                _mark(check, decoded)
            elif type(decoded) is BusStats:
                last = check.last_bus.get(station)
                if last is None or decoded.time_ns >= last.time_ns:
                    check.last_bus[station] = decoded


def _mark(check: RecordingCheck, sample: Sample) -> None:
    check.samples += 1
    marks = check.seen.get((sample.station, sample.run_id))
    if marks is None:
        marks = check.seen[(sample.station, sample.run_id)] = bytearray(sample.sequence + 1)
        check.unexpected += sample.station in check.expected  # once per run never published
    if sample.sequence >= len(marks):
        marks.extend(bytes(sample.sequence + 1 - len(marks)))
    if marks[sample.sequence]:
        check.duplicates += 1
    marks[sample.sequence] = 1
