"""Pair the two sensor frames of a sample and unroll the 16-bit Counter (pure).

A sample is complete when its ``ToolSensors`` and ``JointSensors`` frames,
which carry the same rolling ``Counter``, have both arrived (on a torque-only
station the ``ToolSensors`` frame alone completes it). Samples leave in
Counter order, as soon as they are complete: the stop path is latency-critical.

Faults are counted, never raised:

- a Counter that skips ahead is a gap; the skipped samples are counted as
  missed, but only as many as the time since the last frame can explain: at
  the contract's :data:`SAMPLE_RATE_HZ` the tool cannot have sent more than
  one sample per period, plus :data:`JITTER_SAMPLES` for frames that arrive
  bunched. A longer jump (a corrupt or forged frame, random traffic on the
  sensor id) is not a gap but a counter fault: the frame is dropped, and
  "missed samples" never exceeds what the bus could have carried;
- a repeated or backwards Counter (a replayed or confused node) is dropped;
- the dropped frames are kept as candidates (the newest :data:`CANDIDATES`):
  :data:`RESYNC_FRAMES` dropped frames that go on from each other, as the
  tool's own samples do, show that its Counter itself moved (a restarted
  node, or a forged frame taken first): the count resumes from there
  (``resyncs``), so one bad frame never silences the rest of a run, while a
  flood of random frames (one in about 9000 plausibly follows another) almost
  never moves it;
- a ``ToolSensors`` whose partner has not come by the time the tool is two
  samples further leaves without force (``unpaired``); a partner arriving
  after that, or a ``JointSensors`` with no tool frame, is dropped (``orphans``).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

from shared.contract import COUNTER_MODULO, SAMPLE_RATE_HZ

#: How many samples a ToolSensors frame may wait for its JointSensors partner.
PAIRING_TOLERANCE = 2

#: Counter steps above this count as going backwards rather than a gap ahead.
BACKWARDS_THRESHOLD = COUNTER_MODULO // 2

#: Samples a gap may exceed what the elapsed time explains (frames that arrive bunched).
JITTER_SAMPLES = 5
#: Dropped frames kept to recognise a Counter that really moved ...
CANDIDATES = 32
#: ... when this many in a row go on from each other (random frames almost never do).
RESYNC_FRAMES = 3


@dataclass(frozen=True, slots=True)
class AssembledSample:
    sequence: int  # index in the run, from the unrolled Counter
    time_ns: int  # receive time of the frame that completed the sample
    torque_nm: float
    angle_deg: float
    force_n: float | None


@dataclass(slots=True)
class PairingCounters:
    samples: int = 0
    counter_gaps: int = 0
    missed_samples: int = 0
    repeated: int = 0
    backwards: int = 0
    implausible: int = 0  # jumps ahead longer than the time since the last frame explains
    resyncs: int = 0  # the Counter moved (a run of frames went on from a dropped one)
    unpaired: int = 0
    orphans: int = 0


@dataclass(slots=True)
class _PendingTool:
    sequence: int
    counter: int
    time_ns: int
    torque_nm: float
    angle_deg: float


class SampleAssembler:
    """Turns sensor frames of one run into ordered samples."""

    def __init__(self, has_force_sensor: bool) -> None:
        self.has_force_sensor = has_force_sensor
        self.counters = PairingCounters()
        self._last_counter: int | None = None
        self._last_time_ns = 0
        self._last_sequence = -1
        #: dropped frames (counter, time_ns, frames in a row ending with it), oldest first
        self._candidates: list[tuple[int, int | None, int]] = []
        self._pending_tools: list[_PendingTool] = []  # in sequence order
        self._pending_forces: dict[int, float] = {}  # counter -> force of JointSensors

    def finish_run(self) -> list[AssembledSample]:
        """The run ended: tool frames still waiting leave without force, in order."""
        out = self._flush_older_than(self._last_sequence + 1)
        self.counters.orphans += len(self._pending_forces)
        self._pending_forces.clear()
        return out

    def start_run(self) -> None:
        """A new run: the next ToolSensors frame is sequence 0. Counters keep counting."""
        self._last_counter = None
        self._last_sequence = -1
        self._candidates.clear()
        self._pending_tools.clear()
        self._pending_forces.clear()

    def tool_frame(
        self,
        counter: int,
        torque_nm: float,
        angle_deg: float,
        time_ns: int,
        bus_timed: bool = True,
    ) -> list[AssembledSample]:
        """A ToolSensors frame arrived; returns the samples it completes, in order.

        ``bus_timed``: ``time_ns`` is the bus driver's receive time. When it is not
        (an interface without timestamps: frames read late come bunched), the time
        between frames says nothing of a gap and is not used to judge one.
        """
        sequence = self._unroll(counter, time_ns if bus_timed else None)
        if sequence is None:
            return []
        pending = _PendingTool(sequence, counter, time_ns, torque_nm, angle_deg)
        if not self.has_force_sensor:
            return [self._complete(pending, None, time_ns)]
        force_n = self._pending_forces.pop(counter, None)
        if force_n is not None:
            out = self._flush_older_than(sequence)
            out.append(self._complete(pending, force_n, time_ns))
            return out
        self._pending_tools.append(pending)
        return self._flush_older_than(sequence - PAIRING_TOLERANCE + 1)

    def joint_frame(self, counter: int, force_n: float, time_ns: int) -> list[AssembledSample]:
        """A JointSensors frame arrived; returns the samples it completes, in order."""
        if not self.has_force_sensor:
            return []
        for pending in self._pending_tools:
            if pending.counter == counter:
                out = self._flush_older_than(pending.sequence)
                self._pending_tools.pop(0)  # the matched frame is now the oldest
                out.append(self._complete(pending, force_n, time_ns))
                return out
        # The tool frame has not come yet (or left unpaired already): keep it briefly.
        if len(self._pending_forces) >= PAIRING_TOLERANCE:
            oldest = next(iter(self._pending_forces))
            del self._pending_forces[oldest]
            self.counters.orphans += 1
        self._pending_forces[counter] = force_n
        return []

    def _unroll(self, counter: int, time_ns: int | None) -> int | None:
        """Sequence number of a ToolSensors Counter, counting gaps; None to drop the frame.

        ``time_ns`` None: no receive time to judge a gap by; any jump ahead is a gap.
        """
        if self._last_counter is None:
            step = 1
        else:
            step = (counter - self._last_counter) % COUNTER_MODULO
            if step == 0:
                self.counters.repeated += 1
                return None
            if step > BACKWARDS_THRESHOLD:
                return self._candidate(counter, time_ns, "backwards")
            if time_ns is not None and step > _plausible_steps(time_ns - self._last_time_ns):
                return self._candidate(counter, time_ns, "implausible")
            if step > 1:
                self.counters.counter_gaps += 1
                self.counters.missed_samples += step - 1
        return self._accept(counter, time_ns, step)

    def _accept(self, counter: int, time_ns: int | None, step: int) -> int:
        self._last_counter = counter
        if time_ns is not None:
            self._last_time_ns = time_ns
        self._last_sequence += step
        self._candidates.clear()
        return self._last_sequence

    def _candidate(
        self, counter: int, time_ns: int | None, fault: Literal["backwards", "implausible"]
    ) -> int | None:
        """A frame off the count: dropped, unless it ends a run of dropped frames that go on
        from each other as the tool's own would (:data:`RESYNC_FRAMES`): then it moved."""
        chain = 1
        for old_counter, old_time_ns, old_chain in self._candidates:
            step = (counter - old_counter) % COUNTER_MODULO
            elapsed_ns = 0 if time_ns is None or old_time_ns is None else time_ns - old_time_ns
            if 0 < step <= _plausible_steps(elapsed_ns):
                chain = max(chain, old_chain + 1)
        if chain >= RESYNC_FRAMES:
            self.counters.resyncs += 1
            return self._accept(counter, time_ns, 1)
        if fault == "backwards":
            self.counters.backwards += 1
        else:
            self.counters.implausible += 1
        self._candidates.append((counter, time_ns, chain))
        if len(self._candidates) > CANDIDATES:
            del self._candidates[0]
        return None

    def _complete(
        self, pending: _PendingTool, force_n: float | None, time_ns: int
    ) -> AssembledSample:
        self.counters.samples += 1
        return AssembledSample(
            pending.sequence, time_ns, pending.torque_nm, pending.angle_deg, force_n
        )

    def _flush_older_than(self, sequence: int) -> list[AssembledSample]:
        """Pending tool frames before ``sequence`` leave without force, in order."""
        out = []
        while self._pending_tools and self._pending_tools[0].sequence < sequence:
            pending = self._pending_tools.pop(0)
            self.counters.unpaired += 1
            out.append(self._complete(pending, None, pending.time_ns))
        return out


def _plausible_steps(elapsed_ns: int) -> float:
    """The largest Counter step that ``elapsed_ns`` between two frames can explain."""
    return 1 + JITTER_SAMPLES + max(0, elapsed_ns) * SAMPLE_RATE_HZ / 1e9
