"""One MCAP file being written: schema'd JSON channels, zstd chunks, flush on demand.

Every boltwatch topic becomes a channel whose topic is the zenoh key, with
message encoding ``json`` and a ``jsonschema`` schema named after the
registry name (``boltwatch.Sample`` ...), so Foxglove and the mcap CLI decode
it with no code of ours. Payloads that are not boltwatch messages (unknown
keys) or do not decode are kept byte for byte on a raw channel of the same
topic (schema-less, message encoding :data:`RAW_ENCODING`).

``log_time`` is the receive time in the recorder, ``publish_time`` the
message's own time, ``sequence`` the Sample's sequence (else a per-channel
counter). :meth:`McapSink.flush` closes the chunk in progress, hands it to
the operating system and (``fsync=True``, the default) waits until it is on
the disk, so a killed recorder, and a power cut too, loses only what came
after. The header and metadata reach the operating system when the file is
opened (a full or read-only disk fails at once, not a second later) and the
disk at the first flush, with the folder's entry for the new file: a run's
start waits for no disk (at 50 stations, 40 run starts a second).

A disk that fails (full, read-only, I/O error) raises :class:`OSError` from
any method; the owner then calls :meth:`McapSink.abandon`, which lets go of
the file without writing more (what was flushed stays readable with
``boltwatch recover``) and says how many messages were lost with it.

A chunk ends at every flush, at the file's end and past :data:`_CHUNK_BYTES`;
with :attr:`McapSink.marks` (a spooling station's file) the numbers of the
stations' spools the file holds so far are written last in each chunk
(:mod:`.spool_marks`), so a marker that can be read names only messages on the
disk.

``rename_when_complete=True`` (the recorder's run files): the file is written
under its writing name (:func:`~shared.recordings.layout.writing_path`) and
takes ``path`` only in :meth:`McapSink.close`, once finished and on the disk
(fsync of the file, rename, fsync of the folder: the order rosbag2 and SQLite
keep), so ``path`` never names a broken file whatever stops the process; an
abandoned or killed one keeps its writing name
(:mod:`~shared.recordings.mcap.unfinished_files` finishes it).
"""

from __future__ import annotations

import contextlib
import json
import logging
import os
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import BinaryIO

from mcap.well_known import MessageEncoding, SchemaEncoding
from mcap.writer import CompressionType, Writer

from shared.files import fsync_path
from shared.recordings.layout import writing_path
from shared.recordings.received import Received
from shared.recordings.mcap.mcap_messages import MessageAppender, MessageRow
from shared.recordings.mcap.recording_reader import RAW_ENCODING, RecordingScan
from shared.recordings.mcap.spool_marks import MARKS_TOPIC, FileMarks, marks_channel_metadata
from shared.contract import SpoolFiled, channels, encode, keys
from shared.contract import json_schema
from shared.errors import InputError

LOG = logging.getLogger(__name__)

#: Channel metadata key saying why a raw channel exists.
RAW_REASON = "boltwatch.raw"

_CHUNK_BYTES = 1024 * 1024  # upper bound; flushes close chunks far earlier
#: the writer's own chunk bound, never met: the sink ends each chunk itself (its marks last)
_WRITER_CHUNK_BYTES = 1 << 62


class McapSink:
    """Write :class:`Received` payloads to one new MCAP file (never overwrites)."""

    def __init__(
        self,
        path: Path,
        metadata: Mapping[str, Mapping[str, str]],
        run_id: int | None,
        opened_ns: int,
        library: str = "boltwatch",
        fsync: bool = True,
        rename_when_complete: bool = False,
    ) -> None:
        self.path = path  # its name once complete
        #: where the bytes go until :meth:`close` (``path`` itself unless renamed when complete)
        self.writing_path = writing_path(path) if rename_when_complete else path
        self.run_id = run_id
        self.opened_ns = opened_ns
        self.messages = 0
        self.flushed_messages = 0  # on disk (or at least handed to the OS when fsync is off)
        self.run_ids: set[int] = set()
        self.last_write_ns = opened_ns
        self._fsync = fsync
        self._schemas: dict[str, int] = {}
        self._channels: dict[tuple[str, str], int] = {}
        self._counters: dict[int, int] = {}
        self._unflushed_bytes = 0
        self._chunk_bytes = 0  # written into the chunk in progress
        self._flushed_bytes = 0  # the file's length at the last flush
        #: the spool numbers this file holds (a spooling station's), written last in each chunk
        self.marks: FileMarks | None = None
        self._marks_channels: dict[tuple[str, int], int] = {}
        self._marks_ns = 0
        #: a message of several parts is being written: a full chunk ends after it
        #: (:meth:`end_chunk_if_full`), so that its marks end the chunk that holds it
        self.hold = False
        self._closed = False
        self._abandoned = False
        self._name_synced = not fsync  # the folder's entry for the file, on the disk
        path.parent.mkdir(parents=True, exist_ok=True)
        self._file: BinaryIO = self.writing_path.open("xb")
        try:
            self._writer = Writer(
                self._file, chunk_size=_WRITER_CHUNK_BYTES, compression=CompressionType.ZSTD
            )
            self._writer.start(profile="", library=library)
            self._messages = MessageAppender(self._writer)
            for name, data in metadata.items():
                self._writer.add_metadata(name, dict(data))
            self._writer.flush()  # to the OS: a full or read-only disk fails here, at once
            self._flushed_bytes = self._file.tell()
        except BaseException:
            self.abandon()
            raise

    @property
    def dirty(self) -> bool:
        """True when messages were written since the last flush."""
        return self._unflushed_bytes > 0

    @property
    def size_bytes(self) -> int:
        """Bytes on disk at the last flush plus (uncompressed) bytes written since.

        Read per message by the rotation check, so no system call here: the
        file's length is taken at each flush (``tell()`` is an ``lseek``).
        """
        return self._flushed_bytes + self._unflushed_bytes

    def write(self, received: Received) -> None:
        """Append one payload on its channel."""
        channel_id = self._channel_for(received)
        sequence = received.sequence
        if sequence is None:
            sequence = self._counters.get(channel_id, 0)
            self._counters[channel_id] = sequence + 1
        row = (sequence & 0xFFFFFFFF, received.log_time_ns, received.publish_time_ns)
        self._append(channel_id, [(*row, received.payload)])  # MCAP sequence is uint32
        run_id = received.run_id
        if run_id is not None:
            self.run_ids.add(run_id)

    def write_samples(self, samples: Sequence[Received]) -> None:
        """Append decoded Samples of one station (a batch's, in order) on its samples channel."""
        if not samples:
            return
        channel_id = self._channel_for(samples[0])
        rows = [
            (s.message.sequence & 0xFFFFFFFF, s.log_time_ns, s.publish_time_ns, s.payload)
            for s in samples
        ]
        self._append(channel_id, rows)
        self.run_ids.update({s.message.run_id for s in samples})

    def _append(self, channel_id: int, rows: list[MessageRow]) -> None:
        """Write ``rows`` on the channel and count them (messages, bytes not yet flushed); a
        chunk grown past :data:`_CHUNK_BYTES` ends (to the operating system, not synced)."""
        written = self._messages.add(channel_id, rows)
        self._unflushed_bytes += written
        self._chunk_bytes += written
        self.messages += len(rows)
        self.last_write_ns = rows[-1][1]
        if not self.hold:
            self.end_chunk_if_full()

    def end_chunk_if_full(self) -> None:
        """End the chunk in progress past :data:`_CHUNK_BYTES`: its marks last, then to the
        operating system (not synced)."""
        if self._chunk_bytes >= _CHUNK_BYTES and not self._closed:
            self._write_marks()
            self._writer.flush()
            self._chunk_bytes = 0

    def _write_marks(self) -> None:
        """The spool numbers the file holds, last in the chunk about to end (those changed
        since the last chunk; not counted as messages)."""
        marks = self.marks
        if marks is None or not marks.changed:
            return
        time_ns = self._marks_ns = max(self.last_write_ns, self._marks_ns + 1)  # newest last
        for mark in marks.take(time_ns):
            channel_id = self._marks_channel(mark)
            sequence = self._counters.get(channel_id, 0)
            self._counters[channel_id] = sequence + 1
            row = (sequence & 0xFFFFFFFF, time_ns, time_ns, encode(mark))
            written = self._messages.add(channel_id, [row])
            self._unflushed_bytes += written
            self._chunk_bytes += written

    @property
    def unflushed_messages(self) -> int:
        """Messages written since the last flush: what a failing disk loses."""
        return self.messages - self.flushed_messages

    def flush(self) -> None:
        """Close the chunk in progress, write it through to the OS and (fsync) to the disk."""
        if self._closed or not self.dirty:
            return
        self._write_marks()
        self._writer.flush()
        self._chunk_bytes = 0
        self._sync()
        self._flushed_bytes = self._file.tell()
        self._unflushed_bytes = 0
        self.flushed_messages = self.messages

    def close(self) -> None:
        """Finish the file (summary, index, footer), sync it and give it its name; safe to
        call twice."""
        if self._closed:
            return
        self._closed = True
        try:
            self._write_marks()
            self._writer.finish()
            self._sync()
        finally:
            self._file.close()
        if self.writing_path != self.path:
            os.rename(self.writing_path, self.path)
            if self._fsync:
                fsync_path(self.path.parent)
        self.flushed_messages = self.messages
        LOG.info(
            "closed %s: %d messages, runs %s",
            self.path,
            self.messages,
            ",".join(str(run_id) for run_id in sorted(self.run_ids)) or "-",
        )

    def abandon(self) -> int:
        """Let go of the file without writing more (its disk failed); messages lost with it.

        Never raises. What was flushed stays in the file (under its writing name
        when renamed once complete: :mod:`.unfinished_files` makes it valid); a file
        that holds no message is removed.
        """
        if self._abandoned:
            return 0
        self._abandoned = self._closed = True
        with contextlib.suppress(OSError):
            self._file.close()  # its buffered bytes may fail again: the fd is closed anyway
        self.flushed_messages = self._readable_messages()
        if self.flushed_messages == 0:
            with contextlib.suppress(OSError):
                self.writing_path.unlink()
        return self.messages - self.flushed_messages

    def _readable_messages(self) -> int:
        """Messages a reader finds in the file now: a failed flush may have written them
        all, some, or none (only on the fault path: it reads the file back)."""
        if self.flushed_messages == 0 and self.messages == 0:
            return 0
        try:
            return sum(1 for _ in RecordingScan(self.writing_path).messages())
        except (InputError, OSError):
            return 0

    def _sync(self) -> None:
        if self._fsync:
            os.fsync(self._file.fileno())
            if not self._name_synced:  # the new file's name survives a power cut too
                fsync_path(self.path.parent)
                self._name_synced = True

    def _channel_for(self, received: Received) -> int:
        schema_name = received.schema_name if received.message is not None else None
        if schema_name is None:
            reason = "undecodable" if received.schema_name else "unknown key"
            return self._raw_channel(received.key, reason)
        channel_id = self._channels.get((received.key, schema_name))
        if channel_id is None:
            schema_id = self._schema_id(schema_name)
            channel_id = self._writer.register_channel(
                topic=received.key, message_encoding=MessageEncoding.JSON, schema_id=schema_id
            )
            self._channels[(received.key, schema_name)] = channel_id
        return channel_id

    def _raw_channel(self, key: str, reason: str) -> int:
        channel_id = self._channels.get((key, reason))
        if channel_id is None:
            channel_id = self._writer.register_channel(
                topic=key,
                message_encoding=RAW_ENCODING,
                schema_id=0,
                metadata={RAW_REASON: reason},
            )
            self._channels[(key, reason)] = channel_id
        return channel_id

    def _marks_channel(self, mark: SpoolFiled) -> int:
        """The channel of one spool's marks (its metadata names them: never a raw one)."""
        channel_id = self._marks_channels.get((mark.source, mark.spool_id))
        if channel_id is None:
            channel_id = self._writer.register_channel(
                topic=keys.station_key(mark.station, MARKS_TOPIC),
                message_encoding=MessageEncoding.JSON,
                schema_id=self._schema_id("boltwatch.SpoolFiled", SpoolFiled),
                metadata=marks_channel_metadata(mark.source, mark.spool_id),
            )
            self._marks_channels[(mark.source, mark.spool_id)] = channel_id
        return channel_id

    def _schema_id(self, schema_name: str, message_type: type | None = None) -> int:
        schema_id = self._schemas.get(schema_name)
        if schema_id is None:
            schema = json_schema(message_type or channels.SCHEMA_TYPES[schema_name])
            schema_id = self._writer.register_schema(
                name=schema_name,
                encoding=SchemaEncoding.JSONSchema,
                data=json.dumps(schema).encode(),
            )
            self._schemas[schema_name] = schema_id
        return schema_id

    def __enter__(self) -> McapSink:
        return self

    def __exit__(self, *_exc: object) -> None:
        self.close()
