"""The text ``boltwatch status`` prints for a person at a terminal.

One block per station, one line per figure, labels in a column; what each
figure means is said in :mod:`shared.line_status.station_status`, which collects
them. A figure that did not arrive in the listening window is a ``-`` and a
short guess why, so that an empty line never reads as "all is well". A bridge
station (a controller's, ``kind`` "bridge") has no bus or predictor line unless
their stats came: it runs neither.
"""

from __future__ import annotations

from shared.line_status import (
    BusHealth,
    LastDecision,
    LastRun,
    LastSummary,
    PredictorHealth,
    RecorderHealth,
    StationStatus,
    StatusReport,
    amount_text,
    bridge_lines,
    due_soon_text,
    quality_text,
    result_text,
    spool_text,
)


def format_report(report: StatusReport) -> str:
    """The report for a person at a terminal: one block per station."""
    lines = [f"connected to {report.endpoint}, listened {report.listened_s:.1f} s"]
    if not report.stations:
        lines.append(
            "no station seen: no liveliness tokens and no messages under boltwatch/ "
            "(is anything running? 'boltwatch up' starts the simulated station)"
        )
        return "\n".join(lines)
    for status in report.stations:
        lines.append("")
        lines.extend(_station_lines(status))
    return "\n".join(lines)


_LABEL = 14
#: how a service of :attr:`StationStatus.services` reads where its key is terse
SERVICE_WORDS = {"controller": "controller link"}


def _station_lines(status: StationStatus) -> list[str]:
    def line(label: str, text: str) -> str:
        return f"  {label:<{_LABEL}}{text}"

    services = ", ".join(
        f"{SERVICE_WORDS.get(name, name)} {'up' if alive else 'DOWN'}"
        for name, alive in status.services.items()
    )
    rate = f"{status.samples_per_s:.0f} received"
    if status.bus_samples_per_s is not None:
        rate += f" (bus {status.bus_samples_per_s:.0f})"
    out = [
        f"station {status.station}{_place_text(status.recorder)}",
        line("services", services),
        line("samples/s", rate),
        *_unless_bridge(status, status.bus, line("bus", _bus_text(status.bus))),
        line("tool commands", _commands_text(status)),
        line("last run", _run_text(status.last_run)),
        line("last decision", _decision_text(status.last_decision)),
        line("last summary", _summary_text(status.last_summary)),
        line("last result", result_text(status.last_result)),
        line("quality alert", quality_text(status.quality_alert)),
        line("wear forecast", due_soon_text(status.wear_forecasts)),
        *_unless_bridge(
            status, status.predictor, line("predictor", _predictor_text(status.predictor))
        ),
        line("recorder", _recorder_text(status.recorder)),
        *(line("spool", f"{spool.source}: {spool_text(spool)}") for spool in status.spools),
        *(line(label, text) for label, text in bridge_lines(status.bridge)),
    ]
    if status.unreadable_messages:
        out.append(line("unreadable", f"{status.unreadable_messages} messages"))
    return out


def _place_text(recorder: RecorderHealth | None) -> str:
    """Where the station is, as the recorder's station file says: ``"Wheel nuts" (plant
    North, line B)``, each part only when named; "" when none is."""
    if recorder is None:
        return ""
    named = [f"plant {recorder.plant}"] if recorder.plant else []
    named += [f"line {recorder.line}"] if recorder.line else []
    name = f' "{recorder.station_name}"' if recorder.station_name else ""
    return name + (f" ({', '.join(named)})" if named else "")


def _unless_bridge(status: StationStatus, figure: object, text: str) -> list[str]:
    """``text``, except on a bridge station that did not send ``figure``: it runs no
    acquisition or predictor, so their missing stats say nothing."""
    return [] if status.kind == "bridge" and figure is None else [text]


def _bus_text(bus: BusHealth | None) -> str:
    if bus is None:
        return "- (no BusStats in the window: acquisition down?)"
    return (
        f"{bus.counter_gaps} gaps, {bus.missed_samples} missed samples, "
        f"{bus.bad_frames} bad frames, {bus.receive_errors} receive errors, "
        f"{bus.unsent_samples} unsent samples, {bus.late_decisions} late decisions, "
        f"{bus.bad_decisions} bad decisions "
        f"({bus.frames} frames since start, {bus.age_s:.1f} s ago)"
    )


def _commands_text(status: StationStatus) -> str:
    """What the station commands its tool: a final stage, or stop only and why."""
    bus = status.bus
    if bus is None:
        if status.kind == "bridge":
            return "none: an Open Protocol controller runs its program and stops by itself"
        return "- (no BusStats in the window)"
    if bus.tool_commands == "staged":
        return f"final stage and pulses ({bus.stage_commands} stage commands sent)"
    why = f": {bus.tool_commands_note}" if bus.tool_commands_note else ""
    return f"stop only{why}"


def _predictor_text(predictor: PredictorHealth | None) -> str:
    if predictor is None:
        return "- (no predictor stats in the window: predictor down or not serving it?)"
    return (
        f"{predictor.bad_payloads} bad payloads, {predictor.bad_samples} bad samples, "
        f"{predictor.samples_without_run} samples without a run, "
        f"{predictor.unfinished_runs} unfinished runs ({predictor.age_s:.1f} s ago)"
    )


def _recorder_text(recorder: RecorderHealth | None) -> str:
    if recorder is None:
        return "- (no recorder stats in the window: recorder down or not serving it?)"
    if recorder.lag_p50_ms is None or recorder.lag_max_ms is None:
        lag = "lag - (no samples)"
    else:
        lag = f"lag p50 {recorder.lag_p50_ms:.1f} ms, max {recorder.lag_max_ms:.1f} ms"
    counts = (
        f"{recorder.messages} messages, {recorder.missing_samples} samples missing, "
        f"{recorder.bad_payloads} bad payloads, {recorder.write_errors} write errors, "
        f"{recorder.refused_summaries} run summaries refused by the wear ledger"
    )
    if recorder.waiting_summaries:
        counts += f", {recorder.waiting_summaries} runs waiting for the wear ledger"
    if recorder.waiting_results:
        counts += f", {recorder.waiting_results} results waiting for the results store"
    if recorder.recordings_deleted:
        counts += f", {recorder.recordings_deleted} recordings deleted by the retention policy"
    if recorder.recordings_kept_unstored:
        counts += (
            f", {recorder.recordings_kept_unstored} recordings past their time kept: "
            "results not stored"
        )
    counts += f", {recorder.age_s:.1f} s ago"
    if not recorder.recording:
        return f"NOT RECORDING: {recorder.last_error or 'write failing'} ({lag}, {counts})"
    text = f"recording, {lag}, {counts}"
    if recorder.last_error:
        text += f"; last error: {recorder.last_error}"
    return text


def _run_text(run: LastRun | None) -> str:
    if run is None:
        return "- (no tool state, sample or summary in the window)"
    text = f"{run.run_id} {run.state}"
    if run.tool_id is not None:
        text += f" (tool {run.tool_id}, program {run.program_id})"
    if run.source == "samples":
        text += " (from samples)"
    elif run.source == "runs":
        text += " (from its summary)"
    return text


def _decision_text(decision: LastDecision | None) -> str:
    if decision is None:
        return "- (none in the window)"
    return f"{decision.reason} for run {decision.run_id}, {decision.age_s:.1f} s ago"


def _summary_text(summary: LastSummary | None) -> str:
    if summary is None:
        return "- (none in the window)"
    error = "-" if summary.error_pct is None else f"{summary.error_pct:+.2f} %"
    how = summary.stop_reason or f"tool stopped itself ({summary.tool_state})"
    return (
        f"run {summary.run_id}: {amount_text(summary.reached, summary.unit)} of "
        f"{amount_text(summary.target, summary.unit)} target, error {error}, {how}, "
        f"{summary.events} events, {summary.age_s:.1f} s ago"
    )
