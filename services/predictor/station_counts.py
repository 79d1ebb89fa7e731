"""What the predictor could not use, per served station: counted, published once a second.

The counts are written by the inbox's handler (one message at a time) and
read by the stats publisher in the worker thread; each is a plain integer,
so a reader sees each count whole (one may be a message behind another).
``bad_samples`` adds up the core's input report of every run when the run
ends (or is forgotten): a running run's bad samples show when it ends.
"""

from __future__ import annotations

from dataclasses import dataclass

from shared.contract import PredictorStats
from shared.stickslip import InputReport


@dataclass
class StationCounts:
    """The counts behind one station's :class:`PredictorStats`."""

    station: str
    bad_payloads: int = 0
    bad_samples: int = 0
    samples_without_run: int = 0
    unfinished_runs: int = 0
    repeated_runs: int = 0

    def run_ended(self, report: InputReport) -> None:
        """Add the samples the core of an ended run could not use."""
        self.bad_samples += (
            report.bad_time + report.bad_torque + report.implausible + report.out_of_order
        )

    def stats(self, now_ns: int, started_ns: int) -> PredictorStats:
        return PredictorStats(
            station=self.station,
            time_ns=now_ns,
            started_ns=started_ns,
            bad_payloads=self.bad_payloads,
            bad_samples=self.bad_samples,
            samples_without_run=self.samples_without_run,
            unfinished_runs=self.unfinished_runs,
            repeated_runs=self.repeated_runs,
        )
