"""The runs of one station as the predictor follows them: states and samples in, messages out.

Pure (no zenoh, no clock of its own): the same object serves the line
predictor (:mod:`.service`, fed from zenoh) and the edge predictor
(:mod:`.edge_predictor`, fed on the acquisition's CAN thread). Rules:

- ``running`` starts a run (an :class:`ActiveRun` with the station's
  settings for its program, staged when the tool takes a final stage's
  commands: ``ToolState.commands``); a run id starts once, however its state
  flips (counted in :attr:`repeated_runs`); a ``running`` of a run under way
  is a staged tool's new stage (it halted: ``holding``);
- a new run of the station ends its older ones, unheard (their ``done`` was
  lost in an outage: counted in :attr:`unfinished_runs`, no summary); on a
  multi-spindle station a new run ends the older ones of its own spindle only
  (the spindles of a cycle run at once);
- a multi-spindle station's runs are tallied by cycle (``ToolState.sync_id``):
  the cycle's :class:`~shared.contract.CycleResult` (OK only when every spindle
  is: :mod:`shared.quality.cycle_result`) after its last spindle's summary, or
  when a run of the next cycle starts before every spindle's result came;
- ``done`` / ``aborted`` ends a run: its :class:`TighteningResult` (the summary
  judged against the program's windows: :mod:`shared.quality.run_result`), then its
  :class:`RunSummary`;
- a sample of no running run is dropped and counted;
- a :class:`PartScan` makes its part the station's current part; a run takes
  the part current when it starts, and its result names it (a part scanned
  during a run belongs to the next run; none scanned yet: None) and where it
  came from (``part_source``: ``scanned``);
- the line's answer at start (:meth:`StationRuns.restore_part`: the last part
  the line's recorder heard, asked by :mod:`.part_at_start`) is the current
  part until a scan comes (``restored``: it may be stale); a scan heard first
  wins, the answer is then dropped. No part: ``unknown``.

What it counts (:attr:`counts`, a :class:`~.station_counts.StationCounts`:
runs that started again, runs whose end never arrived, samples of no
running run, samples the core of an ended run could not use) goes out as the
station's ``PredictorStats`` once a second; the logs of faults that can
repeat are rate-limited.
"""

from __future__ import annotations

import logging
import threading
from collections import deque

from services.predictor.active_run import ActiveRun, Outgoing
from services.predictor.served_station import ServedStation
from services.predictor.station_counts import StationCounts
from shared.contract import (
    CycleResult,
    PartScan,
    PartSource,
    RunSummary,
    Sample,
    TighteningResult,
    ToolState,
)
from shared.quality import CycleTally, tightening_result
from shared.runtime import RateLimitedLog

LOG = logging.getLogger(__name__)

#: run ids remembered: a ToolState starting one of them again is ignored
STARTED_RUNS_KEPT = 64


class StationRuns:
    """The active runs of one served station."""

    def __init__(self, served: ServedStation) -> None:
        self.served = served
        self._runs: dict[int, ActiveRun] = {}
        self._started: deque[int] = deque(maxlen=STARTED_RUNS_KEPT)
        self.counts = StationCounts(served.station_id)
        #: the part at the station and where it came from, one reference (replaced whole:
        #: the edge predictor's CAN thread reads it while a zenoh thread sets it)
        self._part: tuple[str | None, PartSource] = (None, "unknown")
        self._part_set = threading.Lock()  # between the two that set it: a scan, the line
        self._cycles = CycleTally(served.station_id, served.station.config.station.spindles)
        self._log_no_program = RateLimitedLog(LOG, logging.ERROR)
        self._log_unfinished = RateLimitedLog(LOG)

    def on_tool(self, state: ToolState) -> list[TighteningResult | RunSummary | CycleResult]:
        """A run state of the station; when it ended a run, the run's result and summary
        (in the order to publish them: a summary's reader finds the result already there),
        then its cycle's common result when it was the cycle's last (a multi-spindle
        station); a run that starts a cycle: the common result of one left incomplete."""
        if state.state == "running":
            run = self._runs.get(state.run_id)
            if run is not None:  # a staged tool's new stage (ToolStage), in the same run
                run.on_tool_stage(state)
                return []
            if not self._start(state):
                return []
            return list(self._cycles.on_start(state))
        if state.state not in ("done", "aborted"):
            return []
        run = self._runs.pop(state.run_id, None)
        if run is None:
            return []
        summary = run.summary(state)
        result = tightening_result(summary, run.program, run.part_id, run.part_source)
        self.counts.run_ended(run.core.input_report)
        LOG.info(
            "%s run %s %s %s, part %s: %d events, stop %s%s, error %s %%, %s",
            state.station,
            state.run_id,
            state.state,
            result.result,
            f"{run.part_id} ({run.part_source})" if run.part_id else "-",
            summary.events,
            summary.stop_reason or "by the tool",
            f" (late decision: {summary.late_decision})" if summary.late_decision else "",
            f"{summary.error_pct:.2f}" if summary.error_pct is not None else "-",
            run.core.input_report.as_dict(),
        )
        cycle = self._cycles.on_result(result)
        return [result, summary] if cycle is None else [result, summary, cycle]

    @property
    def part_id(self) -> str | None:
        """The part at the station (None: none known)."""
        return self._part[0]

    @property
    def part_source(self) -> PartSource:
        """Where the part at the station came from (``unknown``: there is none)."""
        return self._part[1]

    @property
    def part_scanned(self) -> bool:
        """A scan was heard since the start (the line's answer is no longer wanted)."""
        return self._part[1] == "scanned"

    def on_part(self, scan: PartScan) -> None:
        """A part arrived at the station: the runs that start from now on tighten it."""
        with self._part_set:
            if scan.part_id != self.part_id:
                LOG.info("%s: part %s at the station", scan.station, scan.part_id)
            self._part = (scan.part_id, "scanned")

    def restore_part(self, scan: PartScan) -> bool:
        """The line's last scan of the station, asked at start: the current part until a scan
        is heard; False (and nothing changes) when one was heard already."""
        with self._part_set:
            if self.part_scanned:
                return False
            LOG.info(
                "%s: part %s at the station, as the line last heard it (a part that arrived "
                "while the station was down is not known until its next scan)",
                scan.station,
                scan.part_id,
            )
            self._part = (scan.part_id, "restored")
            return True

    def on_sample(self, sample: Sample, wall_ns: int) -> list[Outgoing]:
        """Feed a sample to its run; the events, intensities and decision it produced."""
        run = self._runs.get(sample.run_id)
        if run is None:
            self.counts.samples_without_run += 1
            return []
        return run.on_sample(sample, wall_ns)

    def _start(self, state: ToolState) -> bool:
        """A run starts (False: none did: its id started before)."""
        if state.run_id in self._runs:
            return False
        if state.run_id in self._started:  # a run id starts once, however its state flips
            self.counts.repeated_runs += 1
            return False
        self._started.append(state.run_id)
        self._forget_unfinished_runs(state.spindle)
        try:
            program = self.served.program(state.program_id)
        except KeyError as err:
            self._log_no_program("run %s: %s; not predicting this run", state.run_id, err.args[0])
            return True
        part_id, part_source = self._part  # read once: an edge predictor's scans come on
        # another thread
        settings = self.served.settings(program, state.commands or "stop")
        self._runs[state.run_id] = ActiveRun(state, program, settings, part_id, part_source)
        LOG.debug(
            "%s run %s started (program %s, part %s)",
            state.station,
            state.run_id,
            program.id,
            part_id or "-",
        )
        return True

    def _forget_unfinished_runs(self, spindle: int | None) -> None:
        """A new run of ``spindle`` starts: the older ones of that spindle have ended, unheard
        (an outage)."""
        for run_id, run in list(self._runs.items()):
            if run.state.spindle != spindle:
                continue  # another spindle's run of the cycle: under way beside it
            del self._runs[run_id]
            self.counts.unfinished_runs += 1
            self.counts.run_ended(run.core.input_report)
            self._log_unfinished(
                "%s run %s: its end never arrived (network outage?); no summary, %s",
                run.state.station,
                run_id,
                run.core.input_report.as_dict(),
            )
