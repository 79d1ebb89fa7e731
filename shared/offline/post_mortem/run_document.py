"""One recorded run as plain data for a browser to draw (the line's page), ready for JSON.

:func:`run_document` gives, in the recording's own units:

- ``series``: the samples drawn (every one up to :data:`~.curve_points.MAX_POINTS`) as
  columns: ``time_s`` (since the run's first sample, on the sample's own clock when every
  sample has it, else the receive time: as the overlay and ``export`` count),
  ``torque_nm``, ``angle_deg``, ``force_n`` (None: no preload measured in the run; a
  None inside it: a sample that came without one);
- ``events``: each stick-slip event at its peak (T_max,j, T_min,j, ΔT_j, F_j, ΔF_j,
  f_ss, I_j), and ``plateaus``: each F_j over the stick phase that ends at peak j (as
  ``inspect`` draws them, :func:`~.post_mortem_panels.plateau_bars`);
- ``decisions``: each stop decision (its reason and detail, the torque and preload it
  was decided on, what it predicted, advisory or not); ``stages``: a final stage's
  commands (the switch, a return to the rundown, each pulse, the finish);
- ``result``: the run's :class:`~shared.contract.TighteningResult` in the file (the final
  values with their windows and status, the verdict and why, a controller's steps), None
  when the file holds none; ``target``: the program's target from the file's ``program``
  record (None for a controller's run: that record is the station file's);
  ``controller``: a controller's own windows and target;
- ``samples`` (in the recording), ``drawn`` (sent), ``last`` (the last sample's values),
  ``complete`` and ``state`` (whole, or what was lost), ``files``, ``runs_in_file``.

Every mark carries the time and angle of its sample (the one received at its time, else
the nearest; of several received at once, the one with its torque), so it is drawn over
time and over angle alike. A number that is not finite is None: JSON has no NaN.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any

import numpy as np

from shared.offline.post_mortem.curve_points import (
    MAX_POINTS,
    TIME_DECIMALS,
    drawn_indices,
    json_column,
)
from shared.offline.post_mortem.post_mortem_panels import plateau_bars
from shared.offline.post_mortem.post_mortem_run import RecordedRun


class _Clock:
    """The run's samples as arrays, and where a mark received at ``time_ns`` falls."""

    def __init__(self, run: RecordedRun) -> None:
        samples = run.samples
        self.time_ns = np.array([s.time_ns for s in samples], dtype=np.int64)
        self.torque_nm = np.array([s.torque_nm for s in samples], dtype=np.float64)
        self.angle_deg = np.array([s.angle_deg for s in samples], dtype=np.float64)
        if samples and all(s.time_s is not None for s in samples):
            own = np.array([s.time_s for s in samples], dtype=np.float64)
            self.time_s = own - own[0]
            self.clock = "sample"
        else:
            self.time_s = (self.time_ns - self.time_ns[0]).astype(np.float64) / 1e9
            self.clock = "receive"

    def index(self, time_ns: int, torque_nm: float | None = None) -> int:
        distance = np.abs(self.time_ns - time_ns)
        nearest = np.flatnonzero(distance == distance.min())
        if torque_nm is None or len(nearest) == 1 or not math.isfinite(torque_nm):
            return int(nearest[0])
        return int(nearest[np.argmin(np.abs(self.torque_nm[nearest] - torque_nm))])

    def at(self, time_ns: int, torque_nm: float | None = None) -> dict[str, Any]:
        """The time and angle of the sample a mark belongs to."""
        n = self.index(time_ns, torque_nm)
        return {"time_s": _time(self.time_s[n]), "angle_deg": _number(self.angle_deg[n])}


def run_document(run: RecordedRun, max_points: int = MAX_POINTS) -> dict[str, Any]:
    """``run`` as the page draws it (see the module docstring)."""
    clock = _Clock(run)
    kept = drawn_indices(clock.torque_nm, max_points)
    force = None
    if run.has_force:
        force = json_column(np.array([_or_nan(s.force_n) for s in run.samples])[kept])
    last = run.samples[-1]
    result = run.result
    return {
        "station": last.station,
        "run_id": run.run_id,
        "samples": len(run.samples),
        "drawn": len(kept),
        "clock": clock.clock,
        "series": {
            "time_s": json_column(clock.time_s[kept], TIME_DECIMALS),
            "torque_nm": json_column(clock.torque_nm[kept]),
            "angle_deg": json_column(clock.angle_deg[kept]),
            "force_n": force,
        },
        "last": {
            "time_s": _time(clock.time_s[-1]),
            "torque_nm": _number(last.torque_nm),
            "angle_deg": _number(last.angle_deg),
            "force_n": _number(last.force_n),
        },
        "events": [_event(clock, event) for event in run.events],
        "plateaus": _plateaus(run, clock),
        "decisions": [_decision(clock, decision) for decision in run.decisions],
        "stages": [_stage(clock, stage) for stage in run.stages],
        "result": None if result is None else _finite(dataclasses.asdict(result)),
        "target": _target(run),
        "controller": None if run.controller is None else _controller(run),
        "complete": run.complete,
        "state": run.state,
        "files": [path.name for path in run.sources],
        "runs_in_file": run.runs_in_file,
    }


def _event(clock: _Clock, event: Any) -> dict[str, Any]:
    return clock.at(event.time_ns, event.peak_torque_nm) | {
        "index": event.index,
        "peak_torque_nm": _number(event.peak_torque_nm),
        "min_torque_nm": _number(event.min_torque_nm),
        "torque_drop_nm": _number(event.torque_drop_nm),
        "plateau_force_n": _number(event.plateau_force_n),
        "force_step_n": _number(event.force_step_n),
        "f_ss_hz": _number(event.f_ss_hz),
        "intensity": _number(event.intensity),
    }


def _plateaus(run: RecordedRun, clock: _Clock) -> list[dict[str, Any]]:
    """Each F_j over its stick phase (``plateau_bars``' run times, on the receive clock,
    put on the samples they fall on)."""
    plateaus = []
    for force_n, start_s, end_s in plateau_bars(run):
        start = clock.at(run.t0_ns + round(start_s * 1e9))
        end = clock.at(run.t0_ns + round(end_s * 1e9))
        plateaus.append(
            {
                "force_n": _number(force_n),
                "from_time_s": start["time_s"],
                "to_time_s": end["time_s"],
                "from_angle_deg": start["angle_deg"],
                "to_angle_deg": end["angle_deg"],
            }
        )
    return plateaus


def _decision(clock: _Clock, decision: Any) -> dict[str, Any]:
    return clock.at(decision.time_ns, decision.torque_nm) | {
        "reason": decision.reason,
        "detail": decision.detail,
        "torque_nm": _number(decision.torque_nm),
        "force_n": _number(decision.force_n),
        "predicted_force_n": _number(decision.predicted_force_n),
        "predicted_torque_nm": _number(decision.predicted_torque_nm),
        "advisory": decision.advisory,
    }


def _stage(clock: _Clock, stage: Any) -> dict[str, Any]:
    return clock.at(stage.time_ns, stage.torque_nm) | {
        "command": stage.command,
        "reason": stage.reason,
        "detail": stage.detail,
        "torque_nm": _number(stage.torque_nm),
        "pulse": stage.pulse,
    }


def _target(run: RecordedRun) -> dict[str, Any] | None:
    """The program's target from the file's ``program`` record (a CAN station's run)."""
    if run.controller is not None:
        return None
    program = run.metadata.get("program", {})
    return {
        "program_id": program.get("id") or None,
        "name": program.get("name") or None,
        "torque_nm": _parsed(program.get("target_torque_nm")),
        "force_n": _parsed(program.get("target_force_n")),
    }


def _controller(run: RecordedRun) -> dict[str, Any]:
    marks = run.controller
    assert marks is not None
    return _finite(dataclasses.asdict(marks)) | {"describe": marks.describe()}


def _parsed(text: str | None) -> float | None:
    try:
        return _number(float(text)) if text else None
    except ValueError:
        return None


def _or_nan(value: float | None) -> float:
    return math.nan if value is None else value


def _number(value: float | None) -> float | None:
    return None if value is None or not math.isfinite(value) else float(value)


def _time(value: float) -> float | None:
    return None if not math.isfinite(value) else round(float(value), TIME_DECIMALS)


def _finite(value: Any) -> Any:
    """``value`` (dicts, lists, numbers) with every non-finite float None."""
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    if isinstance(value, dict):
        return {key: _finite(item) for key, item in value.items()}
    if isinstance(value, list | tuple):
        return [_finite(item) for item in value]
    return value
