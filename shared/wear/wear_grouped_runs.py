"""A tool's runs of one production day at one station with one program: what the forecast
reads of the ledger (:func:`~.wear_history.grouped_runs`) and works from."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True, slots=True)
class GroupedRuns:
    """The sums of a tool's runs of one production day, station and program, before or after
    its last service."""

    day: int  # the production day (:meth:`~.wear_calendar.ProductionCalendar.day_of`)
    station: str
    program_id: int
    after_service: bool
    runs: int  # tightenings
    every_run: int  # of either kind
    intensity: float  # Σ I_process
    intensity_sq: float  # Σ I_process²
