"""Read every complete record of an MCAP file, damaged or not, in file order.

A recorder that was killed leaves a file without its summary and footer, and
possibly with a half-written chunk at the end. mcap's indexed reader needs
the footer; its :class:`~mcap.stream_reader.StreamReader` reads record by
record from the start, which is what this module does: it yields every record
up to the first one that is incomplete or fails its CRC, then stops and says
where and why (:attr:`RecordingScan.damage`). Intact files read the same way,
so one code path serves ``recover``, ``export`` and ``inspect``.

Only a regular file is read: a FIFO, a device or a socket named like a
recording (hostile, or a mistake) is refused at once with one line naming
it, never waited on (it is opened without blocking, then checked). A read
that fails (an I/O error) ends the scan like damage.
"""

from __future__ import annotations

import logging
import os
import stat
import struct
from collections.abc import Iterator
from pathlib import Path
from typing import IO, BinaryIO, cast

import zstandard
from mcap.exceptions import EndOfFile, InvalidMagic, McapError
from mcap.records import Channel, Message, Schema
from mcap.stream_reader import StreamReader
from mcap.writer import MCAP0_MAGIC as MCAP_MAGIC

from shared.errors import InputError

LOG = logging.getLogger(__name__)

#: Message encoding of a raw channel: a payload kept byte for byte (not a boltwatch message,
#: or one the recorder refused), on a channel of the same topic as the typed one
RAW_ENCODING = "application/octet-stream"
#: What a damaged tail can raise while a record is parsed or a chunk decompressed.
_DAMAGE = (McapError, ValueError, struct.error, zstandard.ZstdError, EOFError, OSError)
#: what a file that is not a regular one is, in words
_KINDS = (
    (stat.S_ISFIFO, "a FIFO"),
    (stat.S_ISCHR, "a character device"),
    (stat.S_ISBLK, "a block device"),
    (stat.S_ISSOCK, "a socket"),
    (stat.S_ISDIR, "a folder"),
)

McapRecord = object


class _CountedReads:
    """A file read through, counting the bytes read: where the reading is, without asking
    the file (``tell()`` is a system call that lets go of the GIL; once a record, it cost
    a thread of the OPC UA server's pool most of a trace's reading)."""

    def __init__(self, handle: BinaryIO) -> None:
        self._handle = handle
        self.position = 0

    def read(self, size: int = -1) -> bytes:
        data = self._handle.read(size)
        self.position += len(data)
        return data


class RecordingScan:
    """One pass over the records of ``path``; afterwards, whether it was whole.

    ``complete`` is True when the footer was reached; otherwise ``damage``
    says what stopped the reading and ``good_bytes`` how far the complete
    records reach.
    """

    def __init__(self, path: Path) -> None:
        self.path = Path(path)
        self.complete = False
        self.damage: str | None = None
        self.good_bytes = 0
        self.file_bytes = 0
        self.schemas: dict[int, Schema] = {}
        self.channels: dict[int, Channel] = {}

    def records(self) -> Iterator[McapRecord]:
        """Every complete record (chunks opened up), in file order; stops at damage."""
        handle = self._open()
        with handle:
            self.file_bytes = os.fstat(handle.fileno()).st_size
            counted = _CountedReads(handle)
            stream = cast(IO[bytes], counted)  # mcap's reader calls read() only
            reader = StreamReader(stream, validate_crcs=True, record_size_limit=self.file_bytes)
            iterator = iter(reader.records)
            while True:
                try:
                    record = next(iterator)
                except StopIteration:
                    self.complete = True
                    self.good_bytes = self.file_bytes
                    return
                except (InvalidMagic, *_DAMAGE) as err:
                    if self.good_bytes == 0:  # not even magic and header
                        raise self._not_mcap(err, handle) from err
                    cut = isinstance(err, EndOfFile | struct.error | EOFError)
                    if cut and handle.tell() >= self.file_bytes:
                        self.damage = (
                            f"the file is cut off inside a record after byte {self.good_bytes}"
                        )
                    else:
                        self.damage = (
                            f"damaged record after byte {self.good_bytes} "
                            f"({type(err).__name__}: {err}); nothing after it can be read"
                        )
                    return
                self.good_bytes = counted.position
                if isinstance(record, Schema):
                    self.schemas[record.id] = record
                elif isinstance(record, Channel):
                    self.channels[record.id] = record
                yield record

    def _open(self) -> BinaryIO:
        """The file, opened without waiting (a FIFO would wait for a writer), when it is a
        regular file; InputError naming it otherwise."""
        try:
            descriptor = os.open(self.path, os.O_RDONLY | os.O_NONBLOCK | os.O_CLOEXEC)
        except FileNotFoundError as err:
            raise InputError(f"{self.path}: file not found") from err
        except OSError as err:
            raise InputError(f"{self.path}: cannot be read: {err.strerror}") from err
        mode = os.fstat(descriptor).st_mode
        if not stat.S_ISREG(mode):
            os.close(descriptor)
            kind = next((name for test, name in _KINDS if test(mode)), "not a regular file")
            raise InputError(f"{self.path}: {kind}, not a recording: not read")
        os.set_blocking(descriptor, True)
        return os.fdopen(descriptor, "rb")

    def _not_mcap(self, err: Exception, handle: BinaryIO) -> InputError:
        if self.file_bytes == 0:
            return InputError(f"{self.path}: no MCAP data (empty file)")
        try:
            handle.seek(0)
            start = handle.read(len(MCAP_MAGIC))
        except OSError as read_err:
            return InputError(f"{self.path}: cannot be read: {read_err.strerror}")
        if start != MCAP_MAGIC[: len(start)]:
            return InputError(
                f"{self.path}: not an MCAP file (byte 0: {start!r}, expected the MCAP magic "
                f"{MCAP_MAGIC!r})"
            )
        if self.file_bytes <= len(MCAP_MAGIC):
            return InputError(
                f"{self.path}: cut off after {self.file_bytes} bytes, inside the MCAP magic"
            )
        return InputError(
            f"{self.path}: the MCAP header at byte {len(MCAP_MAGIC)} is unreadable "
            f"({type(err).__name__}: {err})"
        )

    def messages(
        self, topic_suffix: str | None = None
    ) -> Iterator[tuple[Schema | None, Channel, Message]]:
        """(schema, channel, message) of every complete message, optionally of topics
        ending in ``topic_suffix``; a message on an unknown channel ends the scan as damage."""
        for record in self.records():
            if not isinstance(record, Message):
                continue
            channel = self.channels.get(record.channel_id)
            if channel is None:
                self.damage = f"message on channel {record.channel_id}, which was never defined"
                return
            if topic_suffix is not None and not channel.topic.endswith(topic_suffix):
                continue
            yield self.schemas.get(channel.schema_id), channel, record

    def typed_messages(
        self, topic_suffix: str | None = None
    ) -> Iterator[tuple[Schema | None, Channel, Message]]:
        """:meth:`messages` without those of raw channels (:data:`RAW_ENCODING`): every
        message a boltwatch decoder took when it was recorded."""
        for schema, channel, message in self.messages(topic_suffix):
            if channel.message_encoding != RAW_ENCODING:
                yield schema, channel, message

    def describe(self) -> str:
        """One line on the file's state, e.g. for a warning."""
        if self.complete:
            return f"{self.path}: complete"
        return (
            f"{self.path}: incomplete, read {self.good_bytes} of {self.file_bytes} bytes, "
            f"{self.file_bytes - self.good_bytes} bytes lost ({self.damage})"
        )
