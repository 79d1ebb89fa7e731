"""Many messages of one channel into an ``mcap`` Writer's open chunk at once.

The ``mcap`` package's :meth:`Writer.add_message` is pure Python and costs
about 3.4 µs a message (a record object, seven small writes, the index and
statistics updated one by one): on a line of 50 stations at 1 kHz that was
the recorder's largest single cost. :class:`MessageAppender` writes a batch's
message records with one ``struct`` pack each into the chunk the writer has
open, updates the writer's chunk index and statistics once per batch and
writes each chunk's message index with one pack, so
the file is the one ``add_message`` would have written, byte for byte
(``tests/unit/shared/recordings/test_mcap_messages.py`` compares them; one difference:
a chunk that reaches the writer's ``chunk_size`` closes after the batch that
filled it, not after the message, and the recorder's flushes close chunks
long before that size).

It reaches into the writer's private chunk builder and statistics
(``mcap`` 1.x). Where they are not what it expects (another version, a writer
without chunks) it says so in one log line and uses ``add_message``: slower,
never wrong.
"""

from __future__ import annotations

import functools
import itertools
import logging
import struct
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

from mcap.data_stream import RecordBuilder
from mcap.opcode import Opcode
from mcap.records import MessageIndex
from mcap.writer import Writer

LOG = logging.getLogger(__name__)

#: opcode, record length, channel id, sequence, log time, publish time (MCAP spec, Message)
_RECORD = struct.Struct("<BQHIQQ")
_MESSAGE_OPCODE = 0x05
_FIXED_BYTES = 2 + 4 + 8 + 8

#: (sequence, log_time_ns, publish_time_ns, data)
MessageRow = tuple[int, int, int, bytes]


def _nothing() -> None:
    return None


@functools.cache
def _tell_one_by_one(module: str) -> None:
    """Once per process: a recorder opens dozens of files a second."""
    LOG.info("%s: writing messages one by one (add_message), the slower way", module)


@dataclass
class _PackedMessageIndex(MessageIndex):
    """A chunk's message index written with one ``struct`` pack (the library's writes
    each entry's two numbers one by one: about 1 µs a message)."""

    def write(self, stream: RecordBuilder) -> None:
        entries = self.records
        stream.start_record(Opcode.MESSAGE_INDEX)
        stream.write2(self.channel_id)
        stream.write4(len(entries) * 16)
        stream.write(struct.pack(f"<{2 * len(entries)}Q", *itertools.chain.from_iterable(entries)))
        stream.finish_record()


class MessageAppender:
    """Append rows of one channel to ``writer``'s open chunk (see the module docstring)."""

    def __init__(self, writer: Writer) -> None:
        self._writer = writer
        chunk = getattr(writer, "_Writer__chunk_builder", None)
        statistics = getattr(writer, "_Writer__statistics", None)
        finalize: Any = getattr(writer, "_Writer__maybe_finalize_chunk", None)
        buffer = getattr(getattr(chunk, "record_writer", None), "_buffer", None)
        usable = (
            chunk is not None
            and hasattr(chunk, "message_indices")
            and hasattr(statistics, "channel_message_counts")
            and callable(finalize)
            and buffer is not None
        )
        if not usable:
            _tell_one_by_one(type(writer).__module__)
        self._chunk: Any = chunk if usable else None
        self._statistics: Any = statistics
        self._finalize: Callable[[], None] = finalize if usable else _nothing

    def add(self, channel_id: int, rows: Sequence[MessageRow]) -> int:
        """Append ``rows`` in order, what ``add_message`` would write for each of them; the
        bytes of their records (header and data)."""
        if not rows:
            return 0
        chunk = self._chunk
        if chunk is None:
            for sequence, log_ns, publish_ns, data in rows:
                self._writer.add_message(channel_id, log_ns, data, publish_ns, sequence)
            return sum(len(row[3]) for row in rows) + _RECORD.size * len(rows)
        # the chunk's buffer is replaced at each chunk's end: looked up per batch
        buffer = chunk.record_writer._buffer
        offset = start = buffer.tell()
        pack = _RECORD.pack
        records: list[bytes] = []
        index: list[tuple[int, int]] = []
        for sequence, log_ns, publish_ns, data in rows:
            record = pack(
                _MESSAGE_OPCODE, _FIXED_BYTES + len(data), channel_id, sequence, log_ns, publish_ns
            )
            index.append((log_ns, offset))
            records.append(record)
            records.append(data)
            offset += len(record) + len(data)
        buffer.write(b"".join(records))
        first_ns, last_ns = min(index)[0], max(index)[0]
        statistics = self._statistics
        if statistics.message_count == 0:
            statistics.message_start_time = first_ns
        else:
            statistics.message_start_time = min(first_ns, statistics.message_start_time)
        statistics.message_end_time = max(last_ns, statistics.message_end_time)
        statistics.channel_message_counts[channel_id] += len(rows)
        statistics.message_count += len(rows)
        if chunk.num_messages == 0:
            chunk.message_start_time = first_ns
        else:
            chunk.message_start_time = min(chunk.message_start_time, first_ns)
        chunk.message_end_time = max(chunk.message_end_time, last_ns)
        indices = chunk.message_indices
        if not indices.get(channel_id):
            indices[channel_id] = _PackedMessageIndex(channel_id=channel_id, records=[])
        indices[channel_id].records.extend(index)
        chunk.num_messages += len(rows)
        self._finalize()
        return offset - start
