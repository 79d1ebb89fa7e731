"""A live run's :class:`TighteningResult`: its summary judged against its program's windows.

One pure function (:func:`tightening_result`), called where the run's
``RunSummary`` is made (:class:`~services.predictor.station_runs.StationRuns`),
for both placements. The final figures are the summary's: the torque and
preload the run reached (after the tool stopped and the joint settled) and
the angle of its last measured sample (since the run started). Each is
judged against the program's window (:mod:`shared.config.program_windows`,
:func:`shared.quality.verdict.judge`).

The run is NOK when a figure is out of its window or has a window and no
value, when the tool aborted the run, or when boltwatch stopped the tool on
a fault (:data:`FAULT_STOPS`: a hard limit, or input too bad to go on);
otherwise OK. A program with no window judges no figure: its runs are OK
unless they aborted or ended on a fault.

The tightening id of a live run is its run id (the tool controller's count
of its tightenings, ``RunId`` on CAN). The part is what the line scanned
last before the run started (``boltwatch/<st>/part``), passed in by the
caller with where it came from (a scan, the line's answer at the predictor's
start); None when no part is known. The batch is unknown to the station
(None). A multi-spindle station's run keeps its spindle and sync id.
"""

from __future__ import annotations

from shared.config import Program
from shared.contract import PartSource, RunSummary, TighteningResult
from shared.quality.verdict import cut_text, figure_reasons, judge, reasons_text, verdict

#: stops boltwatch sends on a fault, not on a good joint: the run is NOK
FAULT_STOPS = frozenset({"torque_limit", "force_limit", "angle_limit", "input_fault"})


def tightening_result(
    summary: RunSummary,
    program: Program,
    part_id: str | None = None,
    part_source: PartSource | None = None,
) -> TighteningResult:
    """The result of the run of ``summary``, tightened with ``program`` on part ``part_id``
    (None: unknown), which came from ``part_source`` (None: not said)."""
    torque = judge(summary.reached_torque_nm, *program.window("torque"))
    angle = judge(summary.reached_angle_deg, *program.window("angle"))
    force = judge(summary.reached_force_n, *program.window("force"))
    reasons = figure_reasons(
        {"torque": (torque, "Nm"), "angle": (angle, "deg"), "preload": (force, "N")}
    )
    if summary.tool_state == "aborted":
        reasons.append("the tool aborted the run")
    if summary.stop_reason in FAULT_STOPS:
        reasons.append(f"stopped on {summary.stop_reason}")
    return TighteningResult(
        station=summary.station,
        tightening_id=summary.run_id,
        run_id=summary.run_id,
        tool_id=summary.tool_id,
        program_id=summary.program_id,
        program_name=cut_text(program.name),
        time_ns=summary.ended_ns,
        part_id=part_id,
        batch_counter=None,
        final_torque_nm=torque,
        final_angle_deg=angle,
        final_force_n=force,
        result=verdict(reasons),
        nok_reasons=reasons_text(reasons),
        stop_reason=summary.stop_reason,
        events=summary.events,
        process_intensity=summary.process_intensity,
        source="predictor",
        part_source=part_source,
        pulses=summary.pulses if summary.commands == "staged" else None,
        spindle=summary.spindle,
        sync_id=summary.sync_id,
    )
