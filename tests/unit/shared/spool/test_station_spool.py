"""A station's store and forward: what the recorder acknowledged is forgotten, what it lacks
is sent again at a bounded rate and only while it answers, the bound drops samples first."""

from __future__ import annotations

import dataclasses
import os
from pathlib import Path

from shared.contract import RunSummary, SampleBatch, SeqRange, SpoolAck, ToolState
from shared.spool import SpoolFile, StationSpool
from tests.support.fuzz.payloads import template

T0_NS = 1_700_000_000_000_000_000
S_NS = 1_000_000_000


class Clock:
    """The spool's two clocks, moved by the test."""

    def __init__(self) -> None:
        self.s = 100.0

    def monotonic(self) -> float:
        return self.s

    def ns(self) -> int:
        return T0_NS + round(self.s * S_NS)


def spool_of(
    tmp_path: Path, clock: Clock, max_bytes: int = 1 << 30, rate: float = 100.0
) -> StationSpool:
    return StationSpool(
        "st1",
        "acquisition",
        SpoolFile(tmp_path / "st1-acquisition.sqlite"),
        max_bytes,
        drain_messages_per_s=rate,
        resend_after_s=3.0,
        clock_ns=clock.ns,
        monotonic=clock.monotonic,
    )


def batch(run_id: int, n: int) -> SampleBatch:
    made: SampleBatch = template("sample_batches", "st1", T0_NS + n, run_id)
    return made


def summary(run_id: int) -> RunSummary:
    made: RunSummary = template("runs", "st1", T0_NS, run_id)
    return made


def ack(spool: StationSpool, through: int, *ranges: tuple[int, int]) -> SpoolAck:
    return SpoolAck(
        "st1", "acquisition", spool.spool_id, T0_NS, through, [SeqRange(a, b) for a, b in ranges]
    )


def keep(spool: StationSpool, message: object) -> int:
    return spool.record("x", b"p" * 100, message)


def test_what_the_recorder_has_is_forgotten_and_the_rest_sent_again_in_order(
    tmp_path: Path,
) -> None:
    clock = Clock()
    spool = spool_of(tmp_path, clock)
    seqs = [keep(spool, batch(1, n)) for n in range(10)]
    assert seqs == list(range(1, 11))
    assert spool.tick() == []  # nobody acknowledged yet: nobody to send to
    spool.on_ack(ack(spool, 3, (6, 7)))  # a cut lost 4, 5 and everything after 7
    clock.s += 1.0
    assert spool.tick() == []  # not old enough to be sent again
    clock.s += 3.0
    again = spool.tick()
    assert [(m.seq, m.kept_before) for m in again] == [(4, 0), (5, 4), (8, 5), (9, 8), (10, 9)]
    stats = spool.stats()
    assert (stats.messages, stats.oldest_seq, stats.head_seq, stats.resent) == (5, 4, 10, 5)
    clock.s += 1.0
    assert spool.tick() == []  # a whole pass went: the next waits for the acknowledgements
    spool.on_ack(ack(spool, 10))
    clock.s += 3.0
    assert spool.tick() == []
    assert spool.stats().messages == 0
    spool.close()


def test_nothing_is_sent_again_when_the_recorder_no_longer_answers(tmp_path: Path) -> None:
    clock = Clock()
    spool = spool_of(tmp_path, clock)
    spool.on_ack(ack(spool, 0))
    for n in range(5):
        keep(spool, batch(1, n))
    clock.s += 6.0  # the last acknowledgement is older than ACK_FRESH_S
    assert spool.tick() == []
    spool.on_ack(ack(spool, 0))
    assert [m.seq for m in spool.tick()] == [1, 2, 3, 4, 5]
    spool.close()


def test_an_acknowledgement_of_another_spool_is_not_taken(tmp_path: Path) -> None:
    clock = Clock()
    spool = spool_of(tmp_path, clock)
    keep(spool, batch(1, 0))
    spool.on_ack(dataclasses.replace(ack(spool, 1), spool_id=spool.spool_id + 1))
    spool.on_ack(dataclasses.replace(ack(spool, 1), station="st2"))
    spool.tick()
    assert spool.stats().messages == 1
    spool.close()


def test_sending_again_keeps_to_its_rate(tmp_path: Path) -> None:
    clock = Clock()
    spool = spool_of(tmp_path, clock, rate=20.0)
    for n in range(100):
        keep(spool, batch(1, n))
    clock.s += 4.0
    sent = 0
    for _ in range(100):  # five seconds in steps of 50 ms
        spool.on_ack(ack(spool, 0))
        sent += len(spool.tick())
        clock.s += 0.05
    assert 95 <= sent <= 100  # 20 a second, and a second's worth at once at most


def test_the_bound_drops_the_oldest_samples_first_and_never_a_record(tmp_path: Path) -> None:
    clock = Clock()
    spool = spool_of(tmp_path, clock, max_bytes=1024 * 1024)
    running = template("tool", "st1", T0_NS, 1)
    assert isinstance(running, ToolState)
    keep(spool, running)
    records = [keep(spool, summary(run_id)) for run_id in range(1, 6)]
    for n in range(3000):  # 1.5 MB as stored: random bytes do not compress
        spool.record("sample_batches", os.urandom(500), batch(1, n))
    spool.tick()
    stats = spool.stats()
    per_batch = len(batch(1, 0).samples)
    assert stats.dropped_messages > 0
    assert stats.dropped_samples == per_batch * stats.dropped_messages
    assert spool._file.stored_bytes <= 1024 * 1024
    assert spool.samples_dropped_here == stats.dropped_samples
    kept = [m.seq for m in spool._file.after(0, 10_000, 2**62, spool._acked)]
    assert set(records) <= set(kept) and 1 in kept  # the records, and the tool state
    spool.close()
    reopened = spool_of(tmp_path, clock, max_bytes=1024 * 1024)
    assert reopened.stats().dropped_samples == stats.dropped_samples  # counted in the file
    assert reopened.samples_dropped_here == 0
    reopened.close()
