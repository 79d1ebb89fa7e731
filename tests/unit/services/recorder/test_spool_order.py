"""Where the recorder files each numbered message of a station's spool: every message once,
every run whole in one file, in order, whatever was lost live and sent again.

A model of a station (its spool: what is not acknowledged is sent again, oldest
first, with the number it holds before it) against the real
:class:`SpoolOrder`, over cuts, resends lost again and samples dropped to keep
the spool's bound that hypothesis draws.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from hypothesis import given, settings
from hypothesis import strategies as st

from services.recorder.live.spool_order import Fate, SpoolOrder
from shared.spool import SeqRanges


@dataclass
class Files:
    """What one StationFiles does with runs: a run start opens the run's file, the rest
    goes on in the open one (opened for the message's run when there is none)."""

    current: list[tuple[int, list[int]]] | None = None  # [(run, seqs)] one element
    made: list[tuple[int, list[int]]] = field(default_factory=list)

    def write(self, seq: int, run_id: int, run_started: bool) -> None:
        if run_started or self.current is None:
            self.current = [(run_id, [])]
            self.made.append(self.current[0])
        self.current[0][1].append(seq)


@dataclass
class Recorder:
    """What the recorder's spool filing does (services/recorder/live/spool_filing.py)."""

    order: SpoolOrder = field(default_factory=SpoolOrder)
    live: Files = field(default_factory=Files)
    holes: list[Files] = field(default_factory=list)
    waiting: dict[int, tuple[int, bool]] = field(default_factory=dict)  # deferred live ones
    keep_waiting: bool = True

    def receive(self, seq: int, run_id: int, run_started: bool, kept_before: int | None) -> None:
        self._receive(seq, run_id, run_started, kept_before)
        while self.order.next_expected in self.waiting:
            ready = self.order.next_expected
            self._receive(ready, *self.waiting.pop(ready), None)

    def _receive(self, seq: int, run_id: int, run_started: bool, kept_before: int | None) -> None:
        routing = self.order.route(seq, run_started, kept_before)
        hole = routing.hole
        if hole is not None and hole.files is None:
            hole.files = Files()
            self.holes.append(hole.files)
            if routing.opened:  # the live files' open run goes on in the hole
                hole.files.current, self.live.current = self.live.current, None
        if routing.fate is Fate.DEFER and kept_before is None and self.keep_waiting:
            self.waiting[seq] = (run_id, run_started)
        if routing.fate in (Fate.SKIP, Fate.DEFER):
            return
        if routing.caught_up and hole is not None:  # the hole's open run back to the live files
            self.live.current, hole.files.current = hole.files.current, None
        files = hole.files if routing.fate is Fate.HOLE and hole is not None else self.live
        files.write(seq, run_id, run_started)
        self.order.filed_as(seq, routing)
        self.order.completed()

    def files(self) -> list[tuple[int, list[int]]]:
        return [made for files in (self.live, *self.holes) for made in files.made]


@dataclass
class Station:
    """The spool: every message until acknowledged; sent again when old enough."""

    starts: set[int]
    kept: SeqRanges = field(default_factory=SeqRanges)
    head: int = 0
    dropped: set[int] = field(default_factory=set)

    def run_of(self, seq: int) -> int:
        return sum(1 for start in self.starts if start <= seq)

    def put(self) -> int:
        self.head += 1
        self.kept.add(self.head)
        return self.head

    def acknowledged(self, filed: SeqRanges) -> None:
        self.kept = SeqRanges(
            (n, n) for first, last in self.kept for n in range(first, last + 1) if n not in filed
        )

    def drop(self, seq: int) -> None:
        if seq in self.kept and seq not in self.starts:
            self.dropped.add(seq)
            self.acknowledged(SeqRanges([(seq, seq)]))

    def again(self, older_than: int) -> list[tuple[int, int]]:
        """(seq, kept before it) of every kept message up to ``older_than``, oldest first."""
        out: list[tuple[int, int]] = []
        before = 0
        for first, last in self.kept:
            for seq in range(first, last + 1):
                if seq > older_than:
                    return out
                out.append((seq, before))
                before = seq
        return out

    @property
    def oldest(self) -> int:
        return next(iter(self.kept))[0] if self.kept.count() else self.head + 1


@dataclass(frozen=True)
class Plan:
    messages: int
    starts: frozenset[int]
    lost_live: frozenset[int]
    lost_again: frozenset[int]  # the n-th message sent again is lost too
    drops: frozenset[int]  # seqs dropped from the spool (a full spool) when produced + 20
    ack_every: int
    keep_waiting: bool  # the recorder keeps deferred live messages in memory


@st.composite
def plans(draw: st.DrawFn) -> Plan:
    messages = draw(st.integers(20, 160))
    starts = {1, *draw(st.sets(st.integers(2, messages), max_size=12))}
    cuts = draw(st.lists(st.tuples(st.integers(1, messages), st.integers(1, 40)), max_size=4))
    lost_live = {n for first, length in cuts for n in range(first, first + length)}
    return Plan(
        messages,
        frozenset(starts),
        frozenset(lost_live),
        frozenset(draw(st.sets(st.integers(0, 300), max_size=30))),
        frozenset(draw(st.sets(st.integers(1, messages), max_size=10))),
        draw(st.integers(1, 15)),
        draw(st.booleans()),
    )


def play(plan: Plan) -> tuple[Recorder, Station]:
    station, recorder = Station(set(plan.starts)), Recorder(keep_waiting=plan.keep_waiting)
    sent_again = 0
    delay = 5  # a message is sent again once this many newer ones were put

    def ack_and_resend() -> None:
        nonlocal sent_again
        station.acknowledged(recorder.order.filed)
        recorder.order.station_has_from(station.oldest)
        for seq, before in station.again(station.head - delay):
            sent_again += 1
            if sent_again not in plan.lost_again:
                recorder.receive(seq, station.run_of(seq), seq in station.starts, before)

    for step in range(1, plan.messages + 1):
        seq = station.put()
        if seq not in plan.lost_live:
            recorder.receive(seq, station.run_of(seq), seq in station.starts, None)
        if step - 20 in plan.drops:
            station.drop(step - 20)
        if step % plan.ack_every == 0:
            ack_and_resend()
    delay = 0
    for _ in range(400):
        if not station.kept.count():
            break
        ack_and_resend()
    return recorder, station


@settings(max_examples=300, deadline=None)
@given(plans())
def test_every_message_is_filed_once_and_every_run_whole_in_one_file(plan: Plan) -> None:
    recorder, station = play(plan)
    assert not station.kept.count(), "the station still waits for acknowledgements"
    written = [seq for _, seqs in recorder.files() for seq in seqs]
    assert len(written) == len(set(written)), "a message filed twice"
    everything = set(range(1, plan.messages + 1))
    assert everything - station.dropped <= set(written), "a message never filed"
    runs_in_files: dict[int, int] = {}
    for run_id, seqs in recorder.files():
        assert seqs == sorted(seqs), f"run {run_id} out of order: {seqs}"
        assert {station.run_of(seq) for seq in seqs} == {run_id}, "two runs in one file"
        runs_in_files[run_id] = runs_in_files.get(run_id, 0) + 1
    assert all(count == 1 for count in runs_in_files.values()), runs_in_files
    assert recorder.order.gone == len(station.dropped - set(written))


def file(order: SpoolOrder, seq: int, run_started: bool, kept_before: int | None) -> Fate:
    """Route ``seq``; file it when it is to be filed; its fate."""
    routing = order.route(seq, run_started, kept_before)
    if routing.fate in (Fate.LIVE, Fate.HOLE):
        order.filed_as(seq, routing)
    return routing.fate


def test_live_runs_go_on_while_a_cut_is_filled_again() -> None:
    """Run 1 (1..5) is cut after 2; run 2 starts live at 6 past the cut: it is filed live at
    once, while 3..5 come again into the hole that holds run 1's file."""
    order = SpoolOrder()
    assert [file(order, seq, seq == 1, None) for seq in (1, 2)] == [Fate.LIVE] * 2
    routing = order.route(6, True, None)
    assert routing.fate is Fate.LIVE and routing.opened and routing.hole is not None
    hole = routing.hole
    assert (hole.first, hole.last) == (3, 5)  # run 1's file is handed to it
    order.filed_as(6, routing)
    assert file(order, 7, False, None) is Fate.LIVE
    assert file(order, 4, False, 3) is Fate.DEFER  # 3 first
    assert [file(order, seq, False, seq - 1) for seq in (3, 4, 5)] == [Fate.HOLE] * 3
    assert order.completed() == [hole]
    assert file(order, 4, False, 3) is Fate.SKIP  # sent again once more: filed already


def test_live_messages_of_a_run_begun_in_a_cut_wait_for_it() -> None:
    """Run 2 starts at 3 inside a cut; its live messages after the cut are deferred (sent
    again later, in order, into run 2's one file) until run 3 starts live."""
    order = SpoolOrder()
    file(order, 1, True, None)
    file(order, 2, False, None)
    routing = order.route(5, False, None)  # 3 (run 2's start) and 4 were lost
    assert routing.fate is Fate.DEFER and routing.opened
    assert file(order, 6, False, None) is Fate.DEFER
    assert file(order, 7, True, None) is Fate.LIVE  # run 3: live again; the hole ends at 6
    assert [file(order, seq, seq == 3, seq - 1) for seq in (3, 4, 5, 6)] == [Fate.HOLE] * 4
    assert order.completed()[0].last == 6
    assert order.deferred == 2


def test_a_recorder_that_restarts_fills_what_it_had_not_saved() -> None:
    filed = SeqRanges([(1, 10), (14, 20)])
    order = SpoolOrder.resumed(filed)
    assert [(h.first, h.next, h.last) for h in order.holes] == [(11, 11, 13)]
    assert order.route(12, False, 11).fate is Fate.DEFER  # 11 first
    routing = order.route(11, False, 10)
    assert routing.fate is Fate.HOLE and not routing.opened
    order.filed_as(11, routing)
    # the station no longer has 12 (dropped to keep its bound): 13 says so
    routing = order.route(13, False, 11)
    assert routing.fate is Fate.HOLE
    order.filed_as(13, routing)
    assert order.gone == 1
    assert [h.last for h in order.completed()] == [13]
    assert order.route(21, False, None).fate is Fate.LIVE


def test_a_number_the_recorder_holds_is_never_gone() -> None:
    """Live 4 and 5 were deferred (kept in the recorder's memory) while the hole from 3 waits;
    the station lost 3 to 5 (its disk was full): its counters say its oldest is 6. 3 is gone;
    4 and 5 are not: the hole stops at 4, where the recorder files what it holds."""
    order = SpoolOrder()
    file(order, 1, True, None)
    file(order, 2, False, None)
    assert [order.route(seq, False, None).fate for seq in (4, 5)] == [Fate.DEFER] * 2
    held = [4, 5]
    assert order.station_has_from(6, lambda first, last: [n for n in held if first <= n <= last])
    assert order.gone == 1 and order.next_expected == 4
