"""Turn a truncated MCAP file (recorder killed) into a valid one.

Every complete record up to the damage is copied into a new file: header,
schemas, channels, messages (times and sequences unchanged), metadata and
attachments; the writer then adds the summary and footer the original lacks.
"""

from __future__ import annotations

import itertools
import logging
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path

from mcap.records import Attachment, Channel, Header, Message, Metadata, Schema
from mcap.writer import CompressionType, Writer

from shared.recordings.mcap.recording_reader import McapRecord, RecordingScan
from shared.errors import InputError, naming

LOG = logging.getLogger(__name__)


@dataclass(frozen=True, slots=True)
class RecoveryReport:
    source: Path
    target: Path
    messages: int
    channels: int
    was_complete: bool
    damage: str | None
    good_bytes: int
    file_bytes: int

    def describe(self) -> str:
        state = (
            "the file was complete"
            if self.was_complete
            else f"read {self.good_bytes} of {self.file_bytes} bytes: {self.damage}"
        )
        return (
            f"recovered {self.messages} messages on {self.channels} channels from "
            f"{self.source} ({state}) into {self.target}"
        )


def default_target(source: Path) -> Path:
    """``run.mcap`` -> ``run.recovered.mcap`` beside it."""
    return source.with_name(f"{source.stem}.recovered.mcap")


def recover(source: Path, target: Path | None = None) -> RecoveryReport:
    """Copy every complete record of ``source`` into a new valid MCAP ``target``."""
    source = Path(source)
    target = default_target(source) if target is None else Path(target)
    if target.resolve() == source.resolve():
        raise InputError(f"{target}: the recovered file must not replace the damaged one")
    scan = RecordingScan(source)
    records = scan.records()
    first = next(records, None)  # a missing, unreadable or non-MCAP source fails here, first
    try:
        with naming(target), target.open("wb") as handle:
            writer = Writer(handle, compression=CompressionType.ZSTD)
            messages, channels = _copy(itertools.chain([first] if first else [], records), writer)
    except BaseException:
        remove_unfinished(target)
        raise
    report = RecoveryReport(
        source=source,
        target=target,
        messages=messages,
        channels=channels,
        was_complete=scan.complete,
        damage=scan.damage,
        good_bytes=scan.good_bytes,
        file_bytes=scan.file_bytes,
    )
    LOG.info("%s", report.describe())
    return report


def remove_unfinished(target: Path) -> None:
    """Remove a half-written ``target`` if it is a regular file; a device or a pipe named as
    the target (``--out /dev/null``) is never removed."""
    if target.is_file():
        target.unlink(missing_ok=True)


def _copy(records: Iterable[McapRecord], writer: Writer) -> tuple[int, int]:
    """Copy complete records into ``writer``; (messages, channels) copied."""
    schema_ids: dict[int, int] = {}
    channel_ids: dict[int, int] = {}
    messages = 0
    started = False
    for record in records:
        if isinstance(record, Header):
            writer.start(profile=record.profile, library=record.library)
            started = True
            continue
        if not started:
            writer.start()
            started = True
        if isinstance(record, Schema) and record.id not in schema_ids:
            schema_ids[record.id] = writer.register_schema(
                record.name, record.encoding, record.data
            )
        elif isinstance(record, Channel) and record.id not in channel_ids:
            channel_ids[record.id] = writer.register_channel(
                record.topic,
                record.message_encoding,
                schema_ids.get(record.schema_id, 0),
                dict(record.metadata),
            )
        elif isinstance(record, Message) and record.channel_id in channel_ids:
            writer.add_message(
                channel_ids[record.channel_id],
                record.log_time,
                record.data,
                record.publish_time,
                record.sequence,
            )
            messages += 1
        elif isinstance(record, Metadata):
            writer.add_metadata(record.name, dict(record.metadata))
        elif isinstance(record, Attachment):
            writer.add_attachment(
                record.create_time, record.log_time, record.name, record.media_type, record.data
            )
    if not started:
        writer.start()
    writer.finish()
    return messages, len(channel_ids)
