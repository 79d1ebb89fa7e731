"""What the recorder says about itself, per station, once a second (:class:`RecorderStats`).

Lag is the receive time in the recorder minus ``Sample.time_ns`` (the CAN
receive time stamped by the acquisition), measured when the recorder's worker
files the sample, over the samples since the previous report (None, not
zero, for a station that sent none). ``bad_payloads`` counts the payloads the
recorder refused (:mod:`shared.recordings.received`) and recorded raw; write
health (``write_errors``, ``last_error``, ``recording``) is the
:class:`~services.recorder.live.recorder.Recorder`'s. ``missing_samples`` is
counted end to end: the acquisition's count of samples it published
(``BusStats.samples``) less the samples received from that station, both
from the first BusStats heard; when the acquisition restarts
(``BusStats.started_ns``) the loss so far is kept and the counting starts
again. Samples a station's spool sends again after a cut count as received
when they are filed (:meth:`RecorderHealth.refiled`): the level drops back to
what the drain could not bring. Why it is counted this way and what it catches:
``docs/explanation/design.md``, "Loss counted end to end".
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field

from shared.config import StationPlace
from shared.contract import QualityAlert, RecorderStats, WearForecast

_NS_PER_MS = 1_000_000


@dataclass
class _StationCounts:
    messages: int = 0
    lags_ns: list[int] = field(default_factory=list)
    samples_received: int = 0
    published_base: int | None = None  # BusStats.samples when counting (re)started
    received_base: int = 0  # samples_received then
    published_last: int = 0
    acquisition_started_ns: int | None = None  # BusStats.started_ns of the counted process
    missing_before_restart: int = 0  # missing samples of earlier acquisition processes
    missing_samples: int = 0
    bad_payloads: int = 0  # refused by the decoder, recorded raw

    def bus_stats(self, published: int, started_ns: int) -> None:
        """The acquisition started at ``started_ns`` has published ``published`` samples."""
        restarted = started_ns != self.acquisition_started_ns or published < self.published_last
        if self.published_base is None or restarted:
            self.missing_before_restart = self.missing_samples
            self.published_base = published
            self.received_base = self.samples_received
            self.acquisition_started_ns = started_ns
        self.published_last = published
        unreceived = (published - self.published_base) - (
            self.samples_received - self.received_base
        )
        self.missing_samples = self.missing_before_restart + max(0, unreceived)


class RecorderHealth:
    """Per-station message counts and sample lags, turned into RecorderStats on demand."""

    def __init__(
        self, stations: list[str], places: Mapping[str, StationPlace] | None = None
    ) -> None:
        """``places``: where each served station is (its station file's plant, line, name)."""
        self._stations: dict[str, _StationCounts] = {name: _StationCounts() for name in stations}
        self._places = dict(places or {})

    @property
    def stations(self) -> list[str]:
        """Served stations first, then every other station seen, in arrival order."""
        return list(self._stations)

    def written(
        self,
        station: str,
        received_ns: int,
        sample_time_ns: int | None,
        is_sample: bool = False,
        refused: bool = False,
    ) -> None:
        """One message of ``station`` written; a Sample's time when it decoded.

        ``is_sample``: it came on the samples key, decodable or not (an
        undecodable one is recorded raw: received, so not missing).
        ``refused``: a payload on a message key the decoder refused (raw).
        """
        counts = self._counts(station)
        counts.messages += 1
        if refused:
            counts.bad_payloads += 1
        if is_sample:
            counts.samples_received += 1
        if sample_time_ns is not None:
            counts.lags_ns.append(received_ns - sample_time_ns)

    def samples_written(self, station: str, received_ns: int, sample_times_ns: list[int]) -> None:
        """Decoded Samples of ``station`` written (a batch's), as :meth:`written` counts each."""
        counts = self._counts(station)
        counts.messages += len(sample_times_ns)
        counts.samples_received += len(sample_times_ns)
        counts.lags_ns += [received_ns - time_ns for time_ns in sample_times_ns]

    def refiled(self, station: str, samples: int) -> None:
        """Samples of ``station`` its spool sent again, filed now: received (no lag: they are
        old by design), so ``missing_samples`` says what is missing after the drain."""
        self._counts(station).samples_received += samples

    def bus_stats(self, station: str, published_samples: int, started_ns: int) -> None:
        """A BusStats of ``station`` arrived: recount its missing samples."""
        self._counts(station).bus_stats(published_samples, started_ns)

    def _counts(self, station: str) -> _StationCounts:
        counts = self._stations.get(station)
        if counts is None:
            counts = self._stations[station] = _StationCounts()
        return counts

    def messages(self, station: str) -> int:
        counts = self._stations.get(station)
        return 0 if counts is None else counts.messages

    def report(
        self,
        now_ns: int,
        write_errors: int,
        last_error: str | None,
        recording: bool,
        refused_summaries: Mapping[str, int] | None = None,
        waiting_summaries: int = 0,
        waiting_results: int = 0,
        quality_alerts: Callable[[str], list[QualityAlert]] | None = None,
        wear_forecasts: Callable[[str], list[WearForecast]] | None = None,
        recordings_deleted: Mapping[str, int] | None = None,
        recordings_kept_unstored: Mapping[str, int] | None = None,
    ) -> list[RecorderStats]:
        """One RecorderStats per station; starts the next lag window.

        ``refused_summaries``: per station, RunSummaries the wear ledger refused;
        ``waiting_summaries``: runs waiting in memory for the ledger (all stations);
        ``waiting_results``: results waiting in memory for the results store (all stations);
        ``quality_alerts``: a station's quality alerts active now;
        ``wear_forecasts``: the forecasts of the station's tools due within a horizon now;
        ``recordings_deleted`` / ``recordings_kept_unstored``: per station, what the
        retention policy deleted since the start / kept at its last pass (results not stored).
        """
        refused = refused_summaries or {}
        deleted = recordings_deleted or {}
        kept_unstored = recordings_kept_unstored or {}
        out: list[RecorderStats] = []
        for station, counts in self._stations.items():
            place = self._places.get(station, StationPlace())
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
                    missing_samples=counts.missing_samples,
                    refused_summaries=refused.get(station, 0),
                    waiting_summaries=waiting_summaries,
                    waiting_results=waiting_results,
                    plant=place.plant,
                    line=place.line,
                    station_name=place.name,
                    bad_payloads=counts.bad_payloads,
                    quality_alerts=quality_alerts(station) if quality_alerts else [],
                    wear_forecasts=wear_forecasts(station) if wear_forecasts else [],
                    recordings_deleted=deleted.get(station, 0),
                    recordings_kept_unstored=kept_unstored.get(station, 0),
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
