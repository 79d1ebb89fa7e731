"""A tool controller's run as a :class:`TighteningResult`, from the controller's own values.

Shared by ``boltwatch import`` (a CS351 controller's file: ``source``
``"import"``) and the Open Protocol bridge (a controller's live MID 0061/0065
result: ``source`` ``"controller"``). Both first say what the controller said
as a :class:`~shared.contract.messages.ControllerResult`: its verdict and, per step, its
tightening functions with nominal and actual values (the import reads them
from the file, the bridge makes one step of the result's torque and angle
limits, targets and finals). The result is made from those, not from our
samples:

- verdict: OK only where the controller's ``result`` and the windows agree:
  NOK when the controller wrote NOK, and NOK when a figure is out of its window
  though the controller wrote OK (a controller that says OK to 9999.99 Nm in a
  100-250 Nm window), the first reason then saying so ("the controller said
  OK, the windows NOK"); where it wrote neither, the windows decide (as for a
  live run). A result never says OK beside a NOK reason;
- windows: the station's own for a figure where the caller gives one
  (``windows``: a controller station's pset in its station file), else the
  controller's (its monitoring functions: for the bridge, the 0061's limits);
- final torque: the last step's ``TF Torque`` actual (else the actual of its
  torque monitoring functions, else of a function named ``Torque`` alone: a
  final value with no function, as a bridge gives a result fetched by id),
  judged against the window of its monitoring functions: ``MF TorqueMin``
  nominal to ``MF(s) TorqueMax`` nominal;
- final angle: the last step's angle (the actual of ``MF AngleMin`` /
  ``MF(s) AngleMax`` / ``TF Angle`` / ``Angle``: the controller counts it in the step),
  judged against ``MF AngleMin`` to ``MF(s) AngleMax``;
- preload: not measured by the controller, not judged;
- steps: each step's name, the tightening function that ended it (``TF ...``)
  with its nominal and actual value, the step's own OK/NOK;
- NOK reasons: the steps the controller marked NOK, then the figures out of
  their windows;
- tightening id: the controller's run id (a CS351's ``cycle``, an Open
  Protocol tightening id); part: its ``part_id`` (``id code``, the VIN);
  batch counter: ``batch_ok`` where the controller keeps a batch (-1 or None
  where it keeps none);
- events, process intensity: the predictor's replay of the run, when given.

Torque values are taken in Nm (the CS351 runs at hand all say ``torque
unit`` Nm; Open Protocol gives Nm).
"""

from __future__ import annotations

from collections.abc import Mapping

from shared.contract import (
    ControllerFunction,
    ControllerResult,
    ControllerStep,
    JudgedFigure,
    ResultSource,
    ResultStep,
    RunSummary,
    StepStatus,
    TighteningResult,
    Verdict,
)
from shared.quality.verdict import cut_text, figure_reasons, judge, reasons_text, verdict

#: a monitoring function's kind by the last word of its name ("MF TorqueMin", "MFs TorqueMax")
MONITORS = ("TorqueMin", "TorqueMax", "AngleMin", "AngleMax")


#: a figure's window: (minimum, maximum), either None for no bound
Window = tuple[float | None, float | None]
#: what the result says first when the controller's verdict and the windows disagree
SAID_OK_WINDOWS_NOK = "the controller said OK, the windows NOK"


def controller_result(
    controller: ControllerResult,
    summary: RunSummary | None,
    program_name: str,
    source: ResultSource,
    tightening_id: int | None = None,
    windows: Mapping[str, Window] | None = None,
) -> TighteningResult:
    """The result of the controller's run; ``summary``: the predictor's replay of it;
    ``tightening_id``: the controller's own id when it is not the run id (a bridge's
    controller whose ids started again: :mod:`services.openprotocol.published_ids`);
    ``windows``: ``"torque"`` / ``"angle"`` -> the station's window for that figure,
    judged in place of the controller's (a window of two None: the controller's)."""
    last = controller.steps[-1] if controller.steps else None
    own = windows or {}
    torque = _figure(last, "Torque", "TF Torque", own.get("torque"))
    angle = _figure(last, "Angle", "TF Angle", own.get("angle"))
    force = judge(None, None, None)
    reasons = [
        f"step {step.name!r} NOK"
        + (f" (quality code {step.quality_code})" if step.quality_code else "")
        for step in controller.steps
        if step.result.upper() == "NOK"
    ]
    out_of_window = figure_reasons({"torque": (torque, "Nm"), "angle": (angle, "deg")})
    said = controller.result.strip().upper()
    if said == "OK" and out_of_window:
        reasons.insert(0, SAID_OK_WINDOWS_NOK)
    elif said == "OK" and reasons:
        reasons.insert(0, "the controller said OK, a step NOK")
    elif said == "NOK" and not reasons and not out_of_window:
        reasons.append("the controller said NOK")
    reasons += out_of_window
    return TighteningResult(
        station=controller.station,
        tightening_id=controller.run_id if tightening_id is None else tightening_id,
        run_id=controller.run_id,
        tool_id=controller.tool_id,
        program_id=controller.program_id,
        program_name=cut_text(program_name),
        time_ns=controller.time_ns,
        part_id=controller.part_id or None,
        batch_counter=(
            controller.batch_ok
            if controller.batch_ok is not None and controller.batch_ok >= 0
            else None
        ),
        final_torque_nm=torque,
        final_angle_deg=angle,
        final_force_n=force,
        result=_verdict(controller.result, reasons),
        nok_reasons=reasons_text(reasons),
        stop_reason=None,  # the controller stopped its tool
        events=summary.events if summary is not None else None,
        process_intensity=summary.process_intensity if summary is not None else None,
        source=source,
        steps=[_step(step) for step in controller.steps],
    )


def _verdict(controller_says: str, reasons: list[str]) -> Verdict:
    """NOK when the controller said so or any reason holds (OK never beside a reason)."""
    if controller_says.strip().upper() == "NOK":
        return "NOK"
    return verdict(reasons)


def _figure(
    step: ControllerStep | None, quantity: str, tightening: str, window: Window | None = None
) -> JudgedFigure:
    """The step's final ``quantity`` ("Torque" or "Angle") against ``window`` where it has a
    bound, else against the step's monitoring window."""
    if step is None:
        return judge(None, None, None)
    monitors = {_monitor(f): f for f in step.functions if _monitor(f) is not None}
    low = monitors.get(f"{quantity}Min")
    high = monitors.get(f"{quantity}Max")
    ends = next((f for f in step.functions if f.name == tightening), None)
    alone = next((f for f in step.functions if f.name == quantity), None)
    value = next(
        (f.actual for f in (ends, low, high, alone) if f is not None and f.actual is not None),
        None,
    )
    if window is not None and (window[0] is not None or window[1] is not None):
        return judge(value, window[0], window[1])
    return judge(
        value,
        low.nominal if low is not None else None,
        high.nominal if high is not None else None,
    )


def _monitor(function: ControllerFunction) -> str | None:
    """``TorqueMin`` for ``MF TorqueMin`` / ``MFs TorqueMin``; None for any other function."""
    words = function.name.split()
    if len(words) == 2 and words[0] in ("MF", "MFs") and words[1] in MONITORS:
        return words[1]
    return None


def _step(step: ControllerStep) -> ResultStep:
    ends = next((f for f in step.functions if f.name.startswith("TF ")), None)
    status: StepStatus = "not_judged"
    if step.result.strip().upper() in ("OK", "NOK"):
        status = "OK" if step.result.strip().upper() == "OK" else "NOK"
    return ResultStep(
        name=step.name,
        function=ends.name if ends is not None else "",
        nominal=ends.nominal if ends is not None else None,
        actual=ends.actual if ends is not None else None,
        status=status,
    )
