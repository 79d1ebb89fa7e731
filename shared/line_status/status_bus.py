"""The acquisition's bus as ``boltwatch status`` shows it: rate and faults from BusStats.

Counters since the acquisition started, from the latest
:class:`~shared.contract.messages.BusStats` of the window; ``bad_frames`` =
wrong_length + decode_errors + error_frames + counter_faults (frames that
were on our bus and unusable; foreign ``unknown_ids`` are not); the
acquisition's own sample rate from the first and the latest BusStats (tells
a slow link from a slow bus). Collected by :mod:`shared.line_status.station_status`.
"""

from __future__ import annotations

from dataclasses import dataclass

from shared.contract import BusStats

_NS = 1_000_000_000


@dataclass(frozen=True)
class BusHealth:
    age_s: float  # since the latest BusStats was received
    frames: int
    samples: int
    counter_gaps: int
    missed_samples: int
    bad_frames: int
    unknown_ids: int
    receive_errors: int
    unpaired: int
    orphans: int
    stop_commands: int
    unsent_samples: int  # published with no router reachable
    late_decisions: int  # decisions for a run the tool was no longer running
    bad_decisions: int = 0  # decision payloads refused (not a valid StopDecision)
    # what the station commands its tool: "stop" (and why, tool_commands_note) or "staged"
    tool_commands: str = "stop"
    tool_commands_note: str = ""
    stage_commands: int = 0  # a final stage's StageCommands sent


def bus_rate(first: BusStats | None, latest: BusStats | None) -> float | None:
    """Samples per second the acquisition counted between two BusStats."""
    if first is None or latest is None or latest.time_ns <= first.time_ns:
        return None
    if latest.samples < first.samples:  # the acquisition restarted in the window
        return None
    return round((latest.samples - first.samples) / ((latest.time_ns - first.time_ns) / _NS), 1)


def bus_health(stats: BusStats | None, received_ns: int, now_ns: int) -> BusHealth | None:
    if stats is None:
        return None
    return BusHealth(
        age_s=round((now_ns - received_ns) / _NS, 3),
        frames=stats.frames,
        samples=stats.samples,
        counter_gaps=stats.counter_gaps,
        missed_samples=stats.missed_samples,
        bad_frames=stats.wrong_length
        + stats.decode_errors
        + stats.error_frames
        + stats.counter_faults,
        unknown_ids=stats.unknown_ids,
        receive_errors=stats.receive_errors,
        unpaired=stats.unpaired,
        orphans=stats.orphans,
        stop_commands=stats.stop_commands,
        unsent_samples=stats.unsent_samples,
        late_decisions=stats.late_decisions,
        bad_decisions=stats.bad_decisions,
        tool_commands=stats.tool_commands,
        tool_commands_note=stats.tool_commands_note,
        stage_commands=stats.stage_commands,
    )
