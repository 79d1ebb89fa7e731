"""MessageAppender writes what mcap's own add_message writes, byte for byte."""

from __future__ import annotations

import io

import pytest
from mcap.reader import make_reader
from mcap.writer import CompressionType, Writer

from shared.recordings.mcap import MessageAppender, MessageRow

T0_NS = 1_700_000_000_000_000_000


def rows(channel: int, count: int, first: int) -> list[MessageRow]:
    return [
        (first + n, T0_NS + (first + n) * 1_000_000, T0_NS + n, b'{"c":%d,"n":%d}' % (channel, n))
        for n in range(count)
    ]


def written(
    batches: list[tuple[int, list[MessageRow]]], appender: bool, **options: object
) -> bytes:
    """A file of two channels whose messages come in ``batches``, flushed after each third."""
    out = io.BytesIO()
    writer = Writer(out, compression=CompressionType.ZSTD, **options)  # type: ignore[arg-type]
    writer.start(profile="", library="test")
    schema = writer.register_schema("s", "jsonschema", b"{}")
    channels = [writer.register_channel(f"t{n}", "json", schema) for n in range(2)]
    messages = MessageAppender(writer)
    for number, (channel, batch) in enumerate(batches):
        if appender:
            messages.add(channels[channel], batch)
        else:
            for sequence, log_ns, publish_ns, data in batch:
                writer.add_message(channels[channel], log_ns, data, publish_ns, sequence)
        if number % 3 == 2:
            writer.flush()
    writer.finish()
    return out.getvalue()


BATCHES = [(n % 2, rows(n % 2, 1 + n % 10, n * 10)) for n in range(20)]
# a message of a channel logged before the ones already in the chunk: start times go back
BATCHES.append((0, [(5, T0_NS - 1, T0_NS, b"{}")]))


@pytest.mark.parametrize("options", [{}, {"use_chunking": False}], ids=["chunks", "no-chunks"])
def test_the_file_is_the_one_add_message_writes(options: dict[str, object]) -> None:
    by_appender = written(BATCHES, appender=True, **options)
    assert by_appender == written(BATCHES, appender=False, **options)
    messages = list(make_reader(io.BytesIO(by_appender)).iter_messages(log_time_order=False))
    expected = [row for _channel, batch in BATCHES for row in batch]
    assert [(m.sequence, m.log_time, m.publish_time, m.data) for _s, _c, m in messages] == expected


def test_an_empty_batch_writes_nothing() -> None:
    assert written([(0, [])], appender=True) == written([], appender=False)
