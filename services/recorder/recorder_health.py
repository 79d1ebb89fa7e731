"""What the recorder says about itself, per station, once a second (:class:`RecorderStats`).

Lag is the receive time in the recorder minus ``Sample.time_ns`` (the CAN
receive time stamped by the acquisition), measured when the recorder's worker
takes the sample off its queue: it includes the network and the queue, so a
recorder falling behind shows here before it loses anything. Each report
covers the samples since the previous report (about one second); a station
that sent no samples has no lag (None), not zero.

Write health (``write_errors``, ``last_error``, ``recording``) is read from
the :class:`~services.recorder.recorder.Recorder`'s ``write_errors``,
``last_write_error`` and ``recording_ok`` attributes; until the Recorder
has them (disk-fault handling lands separately) they read as healthy.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from shared.messages import RecorderStats

_NS_PER_MS = 1_000_000


@dataclass
class _StationCounts:
    messages: int = 0
    lags_ns: list[int] = field(default_factory=list)


class RecorderHealth:
    """Per-station message counts and sample lags, turned into RecorderStats on demand."""

    def __init__(self, stations: list[str]) -> None:
        self._stations: dict[str, _StationCounts] = {name: _StationCounts() for name in stations}

    @property
    def stations(self) -> list[str]:
        """Served stations first, then every other station seen, in arrival order."""
        return list(self._stations)

    def written(self, station: str, received_ns: int, sample_time_ns: int | None) -> None:
        """One message of ``station`` written; ``sample_time_ns`` for Samples only."""
        counts = self._stations.get(station)
        if counts is None:
            counts = self._stations[station] = _StationCounts()
        counts.messages += 1
        if sample_time_ns is not None:
            counts.lags_ns.append(received_ns - sample_time_ns)

    def messages(self, station: str) -> int:
        counts = self._stations.get(station)
        return 0 if counts is None else counts.messages

    def report(
        self, now_ns: int, write_errors: int, last_error: str | None, recording: bool
    ) -> list[RecorderStats]:
        """One RecorderStats per station; starts the next lag window."""
        out: list[RecorderStats] = []
        for station, counts in self._stations.items():
            p50_ms, max_ms = lag_figures_ms(counts.lags_ns)
            counts.lags_ns = []
            out.append(
                RecorderStats(
                    station=station,
                    time_ns=now_ns,
                    messages=counts.messages,
                    lag_p50_ms=p50_ms,
                    lag_max_ms=max_ms,
                    write_errors=write_errors,
                    last_error=last_error,
                    recording=recording,
                )
            )
        return out


def lag_figures_ms(lags_ns: list[int]) -> tuple[float | None, float | None]:
    """(median, max) in milliseconds, rounded to µs; (None, None) with no samples."""
    if not lags_ns:
        return None, None
    ordered = sorted(lags_ns)
    middle = len(ordered) // 2
    if len(ordered) % 2:
        median_ns = float(ordered[middle])
    else:
        median_ns = (ordered[middle - 1] + ordered[middle]) / 2
    return round(median_ns / _NS_PER_MS, 3), round(ordered[-1] / _NS_PER_MS, 3)
