"""The panels of the post-mortem report (:mod:`run_plot`): one function per paper figure.

Each function draws measured values of a :class:`RecordedRun` over run time
and, when :class:`Bounds` has a model, the analytical lines evaluated at model
time (run time + the clock's offset): solid for full relief, dashed for the
paper's 50 % relief (Figures 13-15).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from shared.contract import StickSlipEvent, StopDecision
from shared.model import PAPER_PARTIAL_RELIEF, JointModel
from shared.offline.post_mortem.post_mortem_errors import HORIZONS, PredictionError
from shared.offline.post_mortem.post_mortem_run import ModelClock, RecordedRun

HORIZON_COLORS = {1: "tab:red", 2: "tab:green", 3: "tab:blue"}  # as Figures 18, 22, 23
BOUND_COLOR = "tab:orange"
WINDOW_COLOR = "tab:green"  # a controller's window (its own, from its result)
GRID_POINTS = 400
SMALL = 8  # legend font size
#: The one sign convention of the error panels (Figs. 22, 23), first line of their y labels.
ERROR_SIGN = "measured − predicted"


@dataclass(frozen=True, slots=True)
class Bounds:
    """The model of the run, if any, and the run-time grids its lines are drawn on."""

    model: JointModel | None
    clock: ModelClock | None
    trace_run_s: np.ndarray  # the whole run where model time > 0
    event_run_s: np.ndarray  # from shortly before the first event to the run's end

    @staticmethod
    def of(run: RecordedRun) -> Bounds:
        empty = np.zeros(0)
        model = run.model()
        clock = run.model_clock(model) if model is not None else None
        if model is None or clock is None:
            return Bounds(None, None, empty, empty)
        end_s = run.run_time_s(run.samples[-1].time_ns)
        grid = np.linspace(0.0, end_s, GRID_POINTS)
        trace = grid[clock.model_time_s(grid) > 1e-3]
        first_s = run.run_time_s(run.events[0].time_ns) if run.events else 0.0
        start_s = max(first_s - 0.1 * (end_s - first_s), float(trace[0]) if trace.size else 0.0)
        events = np.linspace(start_s, end_s, GRID_POINTS)
        return Bounds(model, clock, trace, events)

    def model_time_s(self, run_time_s: np.ndarray) -> np.ndarray:
        assert self.clock is not None
        result: np.ndarray = self.clock.model_time_s(run_time_s)
        return result


def _note(ax: Any, text: str) -> None:
    ax.text(0.5, 0.5, text, transform=ax.transAxes, ha="center", va="center", color="gray")


def _legend(ax: Any, loc: str = "upper right") -> None:
    if ax.get_legend_handles_labels()[0]:
        ax.legend(loc=loc, fontsize=SMALL)


def _decision_label(decision: StopDecision) -> str:
    if decision.advisory:
        return f"replayed stop decision ({decision.reason}, not acted on)"
    return f"stop decision ({decision.reason})"


def _decisions(ax: Any, run: RecordedRun) -> None:
    for n, decision in enumerate(run.decisions):
        ax.axvline(
            run.run_time_s(decision.time_ns),
            color="black",
            ls="--",
            lw=1.2,
            label=_decision_label(decision) if n == 0 else None,
        )


#: how each command of a final stage is drawn: (line style, its legend's words)
_STAGE_LINES = {
    "final": (":", "final stage from here"),
    "rundown": (":", "back to the rundown speed"),
    "pulse": ("-.", "pulse back to the target"),
}


def _stages(ax: Any, run: RecordedRun) -> None:
    """A final stage's switch, a return to the rundown, each pulse: a teal vertical line."""
    labelled: set[str] = set()
    for stage in run.stages:
        style = _STAGE_LINES.get(stage.command)
        if style is None:  # a pulse's halt and the finish: the decision's line says enough
            continue
        ls, words = style
        label = None
        if stage.command not in labelled:
            labelled.add(stage.command)
            label = words if stage.command != "pulse" else f"{words} ({stage.reason})"
        at_s = run.run_time_s(stage.time_ns)
        ax.axvline(at_s, color="tab:cyan", ls=ls, lw=1.2, label=label)


def _target(ax: Any, run: RecordedRun, key: str, scale: float = 1.0) -> None:
    """The program's target from the file's ``program`` record; a controller's run: none
    (that record is the station file's, not the controller's pset)."""
    if run.controller is not None:
        return
    try:
        value = float(run.metadata.get("program", {})[key]) * scale
    except (KeyError, ValueError):
        return
    ax.axhline(value, color="tab:purple", ls=":", lw=1.2, label=f"program target {value:g}")


def _controller_torque(ax: Any, run: RecordedRun) -> None:
    """A controller's run: its own torque window (shaded) and target (its result's)."""
    marks = run.controller
    if marks is None:
        return
    low, high = marks.torque_window_nm
    if marks.loosening:  # drawn as magnitudes, as its torque
        low, high = (None if v is None else abs(v) for v in (low, high))
        if low is not None and high is not None and low > high:
            low, high = high, low
    if low is not None and high is not None:
        ax.axhspan(low, high, color=WINDOW_COLOR, alpha=0.15,
                   label=f"controller's torque window {low:g} to {high:g} Nm")  # fmt: skip
    else:
        for bound, side in ((low, "min"), (high, "max")):
            if bound is not None:
                ax.axhline(bound, color=WINDOW_COLOR, lw=1.2,
                           label=f"controller's torque {side} {bound:g} Nm")  # fmt: skip
    if marks.torque_target_nm is not None:
        target = abs(marks.torque_target_nm) if marks.loosening else marks.torque_target_nm
        ax.axhline(target, color="tab:purple", ls=":", lw=1.2,
                   label=f"controller's target {target:g} Nm")  # fmt: skip


def _times(run: RecordedRun, events: Sequence[StickSlipEvent]) -> list[float]:
    return [run.run_time_s(e.time_ns) for e in events]


def draw_torque(ax: Any, run: RecordedRun, bounds: Bounds) -> None:
    """Figure 10 (top): torque, peaks T_max,j, envelopes T_stick and T_slip, the stop."""
    times = [run.run_time_s(s.time_ns) for s in run.samples]
    if run.controller is not None and run.controller.loosening:  # the load, as the replay saw it
        torques = [abs(s.torque_nm) for s in run.samples]
        ax.plot(times, torques, color="tab:blue", lw=0.8, label="torque |T| (a loosening)")
    else:
        torques = [s.torque_nm for s in run.samples]
        ax.plot(times, torques, color="tab:blue", lw=0.8, label="torque T")
    if run.events:
        ax.plot(
            _times(run, run.events),
            [e.peak_torque_nm for e in run.events],
            "v",
            color="tab:red",
            ms=6,
            label="detected peak T_max,j",
        )
    if bounds.model is not None and bounds.trace_run_s.size:
        t = bounds.model_time_s(bounds.trace_run_s)
        ax.plot(bounds.trace_run_s, bounds.model.peak_torque_nm(t), color=BOUND_COLOR, lw=1.5,
                label="T_max: sticking breaks (eqs. 9, 19)")  # fmt: skip
        ax.plot(bounds.trace_run_s, bounds.model.slip_torque_nm(t), color=BOUND_COLOR, lw=1.5,
                ls="-.", label="T_min: end of the smallest slip (eqs. 10, 20)")  # fmt: skip
    _target(ax, run, "target_torque_nm")
    _controller_torque(ax, run)
    _decisions(ax, run)
    _stages(ax, run)
    extra = "" if bounds.model is not None else " (no analytical envelopes)"
    ax.set(title=f"Fig. 10 (top): torque with detected peaks{extra}", ylabel="torque T / Nm")
    ax.set_xlabel("run time / s")
    _legend(ax, "upper left")


def plateau_bars(run: RecordedRun) -> list[tuple[float, float, float]]:
    """(F_j, start, end) of each plateau over the stick phase that ends at peak j, run time s.

    The stick phase of event j runs from the previous peak (the slip of j-1) to
    peak j; the first one gets the length of the next period (or 20 % of the run).
    """
    bars: list[tuple[float, float, float]] = []
    previous_s: float | None = None
    for n, event in enumerate(run.events):
        peak_s = run.run_time_s(event.time_ns)
        start_s = previous_s
        if start_s is None:
            later = run.events[n + 1].period_s if n + 1 < len(run.events) else None
            span = later or 0.2 * run.run_time_s(run.samples[-1].time_ns)
            start_s = max(0.0, peak_s - span)
        if event.plateau_force_n is not None:
            bars.append((event.plateau_force_n, start_s, peak_s))
        previous_s = peak_s
    return bars


def draw_force(ax: Any, run: RecordedRun, bounds: Bounds) -> None:
    """Figure 10 (bottom): preload, plateaus F_j over their stick phases, envelopes, the stop."""
    title = "Fig. 10 (bottom): preload force with plateaus F_j (each over its stick phase)"
    ax.set(title=title, xlabel="run time / s", ylabel="preload F / kN")
    forces = [(run.run_time_s(s.time_ns), s.force_n / 1e3) for s in run.samples if s.force_n]
    if not forces:
        _note(ax, "no preload force in this run (torque-only recording)")
        return
    ax.plot(*zip(*forces, strict=True), color="tab:green", lw=0.8, label="preload F")
    bars = plateau_bars(run)
    if bars:
        values, starts, ends = zip(*bars, strict=True)
        ax.hlines([v / 1e3 for v in values], starts, ends, color="black", lw=2.5,
                  label="plateau F_j (stick phase ending at peak j)")  # fmt: skip
    if bounds.model is not None and bounds.trace_run_s.size:
        t = bounds.model_time_s(bounds.trace_run_s)
        ax.plot(bounds.trace_run_s, bounds.model.force_at_stick_n(t) / 1e3, color=BOUND_COLOR,
                lw=1.5, label="F_min: k_s φ_b,min, sticking breaks (eq. 16)")  # fmt: skip
        ax.plot(bounds.trace_run_s, bounds.model.force_at_slip_n(t) / 1e3, color=BOUND_COLOR,
                lw=1.5, ls="-.", label="F_max: k_s φ_b,max, smallest slip (eq. 17)")  # fmt: skip
    _target(ax, run, "target_force_n", 1e-3)
    _decisions(ax, run)
    _legend(ax, "upper left")


def _band(ax: Any, bounds: Bounds, low: Any, high: Any, scale: float, label: str) -> None:
    """Full-relief band (solid, filled) and 50 % relief lines (dashed) of one bound pair."""
    assert bounds.model is not None
    run_s = bounds.event_run_s
    t = bounds.model_time_s(run_s)
    partial = bounds.model.with_relief(PAPER_PARTIAL_RELIEF)
    lo, hi = low(bounds.model, t) * scale, high(bounds.model, t) * scale
    ax.fill_between(run_s, lo, hi, color=BOUND_COLOR, alpha=0.15)
    ax.plot(run_s, lo, color=BOUND_COLOR, lw=1.2, label=f"{label} min / max")
    ax.plot(run_s, hi, color=BOUND_COLOR, lw=1.2)
    ax.plot(run_s, low(partial, t) * scale, color=BOUND_COLOR, ls="--", lw=1, label="50 % relief")
    ax.plot(run_s, high(partial, t) * scale, color=BOUND_COLOR, ls="--", lw=1)


def _measured(
    ax: Any, run: RecordedRun, values: Sequence[tuple[StickSlipEvent, float | None]], label: str
) -> bool:
    points = [(run.run_time_s(e.time_ns), v) for e, v in values if v is not None]
    if points:
        ax.plot(*zip(*points, strict=True), "o", color="tab:blue", ms=4, label=label)
    return bool(points)


def draw_event_figures(axes: Sequence[Any], run: RecordedRun, bounds: Bounds) -> None:
    """Figures 13-15 (top): f_ss, ΔF and ΔT per event with the bounds of eqs. 21-26."""
    f_ax, step_ax, drop_ax = axes
    events = run.events
    specs = (
        (f_ax, [(e, e.f_ss_hz) for e in events], "f_ss / Hz", "Fig. 13: stick-slip frequency f_ss",
         "f_ss (eqs. 25, 26)", JointModel.stick_slip_frequency_min_hz,
         JointModel.stick_slip_frequency_max_hz, 1.0),
        (step_ax, [(e, None if e.force_step_n is None else e.force_step_n / 1e3) for e in events],
         "ΔF / kN", "Fig. 14: force step ΔF", "ΔF (eqs. 23, 24)", JointModel.force_step_min_n,
         JointModel.force_step_max_n, 1e-3),
        (drop_ax, [(e, e.torque_drop_nm) for e in events], "ΔT / Nm", "Fig. 15: torque drop ΔT",
         "ΔT (eqs. 21, 22)", JointModel.torque_drop_min_nm, JointModel.torque_drop_max_nm, 1.0),
    )  # fmt: skip
    for ax, values, ylabel, title, band_label, low, high, scale in specs:
        ax.set(title=title, xlabel="run time / s", ylabel=ylabel)
        drawn = _measured(ax, run, values, "measured per event")
        if bounds.model is not None:
            _band(ax, bounds, low, high, scale, band_label)
            _fit_to_measured(ax, [v for _, v in values if v is not None])
        if not drawn:
            _note(ax, "no measured values" if ax is not step_ax or run.has_force else "no force")
        _legend(ax)


def _fit_to_measured(ax: Any, values: Sequence[float]) -> None:
    """Keep bounds that shoot off (f_ss ∝ 1/t) from squashing the measured points."""
    if not values:
        return
    low, high = ax.get_ylim()
    top = max(values)
    if high > 4.0 * top > 0.0:
        ax.set_ylim(min(0.0, low), 4.0 * top)


def draw_constants(axes: Sequence[Any], run: RecordedRun, bounds: Bounds) -> None:
    """Figures 13-15 (bottom): K1, K2, K3 per event with the bands of eqs. 34-39."""
    k1_ax, k2_ax, k3_ax = axes
    events = run.events
    bands = bounds.model.constant_bands() if bounds.model is not None else None
    for ax, name, unit, eq, values in (
        (k1_ax, "K1", "-", "eq. 31", [(e, e.k1) for e in events]),
        (k2_ax, "K2", "N·rad/s²", "eq. 32", [(e, e.k2) for e in events]),
        (k3_ax, "K3", "Nm·rad/s²", "eq. 33", [(e, e.k3) for e in events]),
    ):
        ax.set(title=f"{name} ({eq})", xlabel="run time / s", ylabel=f"{name} / {unit}")
        recorded = _measured(ax, run, values, f"{name} recorded (t = run time)")
        if bands is not None:
            lo, hi = getattr(bands, f"{name.lower()}_min"), getattr(bands, f"{name.lower()}_max")
            ax.axhspan(lo, hi, color=BOUND_COLOR, alpha=0.15)
            ax.axhline(lo, color=BOUND_COLOR, lw=1.2, label=f"{name} band (eqs. 34-39)")
            ax.axhline(hi, color=BOUND_COLOR, lw=1.2)
        if not recorded:
            _note(ax, f"no {name} recorded")
    if bounds.model is not None and bounds.clock is not None:
        speed = bounds.model.motor_speed_rad_s
        clock = bounds.clock
        k1_model = [
            (e, e.f_ss_hz * clock.model_time_s(run.run_time_s(e.time_ns)))
            if e.f_ss_hz
            else (e, None)
            for e in events
        ]
        k3_model = [
            (e, e.torque_drop_nm / clock.model_time_s(run.run_time_s(e.time_ns)) * speed)
            if e.torque_drop_nm is not None else (e, None)
            for e in events
        ]  # fmt: skip
        for ax, values, name in ((k1_ax, k1_model, "K1"), (k3_ax, k3_model, "K3")):
            points = [(run.run_time_s(e.time_ns), v) for e, v in values if v is not None]
            if points:
                ax.plot(*zip(*points, strict=True), "s", mfc="none", color="tab:red", ms=5,
                        label=f"{name} at model time t")  # fmt: skip
    for ax in axes:
        _legend(ax)


def draw_error_panels(
    absolute: Sequence[Any],
    relative: Sequence[Any],
    run: RecordedRun,
    errors: Sequence[PredictionError],
) -> None:
    """Figures 22 and 23: absolute and relative errors of the 1st-3rd predictions.

    Every panel is measured − predicted (see :mod:`post_mortem_errors`), and its
    y label says so: above zero the prediction fell short, below it overshot.
    """
    specs = (
        ("peak torque", "T_j − T'_j / Nm", lambda e: e.torque_error_nm,
         "(T_j − T'_j)/T_j = ε_T (62) / %", lambda e: e.relative_torque),
        ("plateau force", "F_j − F'_j / kN",
         lambda e: None if e.force_error_n is None else e.force_error_n / 1e3,
         "(F_j − F'_j)/F_j = ε_F (63) / %", lambda e: e.relative_force),
        ("time", "t_j − t'_j / ms", lambda e: e.time_error_s * 1e3,
         "(t_j − t'_j)/Δt_j = −ε_t (61) / %", lambda e: e.relative_time),
    )  # fmt: skip
    times = {e.index: run.run_time_s(e.time_ns) for e in run.events}
    for abs_ax, rel_ax, (what, abs_label, abs_of, rel_label, rel_of) in zip(
        absolute, relative, specs, strict=True
    ):
        abs_ax.set(title=f"Fig. 22: prediction error, {what}", xlabel="run time / s")
        abs_ax.set_ylabel(f"{ERROR_SIGN}\n{abs_label}")
        rel_ax.set(title=f"Fig. 23: relative prediction error, {what}", xlabel="run time / s")
        rel_ax.set_ylabel(f"{ERROR_SIGN}\n{rel_label}")
        drawn = False
        for horizon in HORIZONS:
            mine = [e for e in errors if e.horizon == horizon]
            for ax, value_of, scale in ((abs_ax, abs_of, 1.0), (rel_ax, rel_of, 100.0)):
                points = [(times[e.index], value_of(e)) for e in mine if value_of(e) is not None]
                if points:
                    x, y = zip(*points, strict=True)
                    ax.plot(x, [v * scale for v in y], "o-", color=HORIZON_COLORS[horizon],
                            ms=3.5, lw=0.8, label=f"{_ordinal(horizon)} prediction")  # fmt: skip
                    drawn = True
        for ax in (abs_ax, rel_ax):
            ax.axhline(0.0, color="gray", lw=0.8)
            if drawn:
                _legend(ax)
            else:
                _note(ax, "no predictions to compare" if what != "plateau force" or run.has_force
                      else "no force")  # fmt: skip


def _ordinal(n: int) -> str:
    return {1: "1st", 2: "2nd", 3: "3rd"}.get(n, f"{n}th")
