"""A controller's own marks of a run: the windows and target it tightened to, for the post-mortem.

A run a tool controller tightened (an Open Protocol bridge's, live; or a
controller's file brought in by ``boltwatch import``) carries the controller's
own word in its recording: a :class:`~shared.contract.messages.ControllerResult` on
``controller`` and the :class:`~shared.contract.messages.TighteningResult` made from it
on ``results`` (``source`` ``controller`` or ``import``). What the run was
aimed at is there: the windows of its final torque and angle (the
controller's monitoring functions, ``MF TorqueMin`` ... ``MF AngleMax``) and
its target (the last step's tightening function, ``TF Torque`` or ``TF
Angle``, and its nominal value), and whether the run was a loosening (its
torque is then drawn as the replay saw it: its magnitude).

The station file's program of the same id is not: on a CAN station file it
is the station's own program (the simulated joint's demo program, whose
target and the paper's model bands of its joint have nothing to do with the
controller's pset), and a controller station's pset carries a name and
windows of the file, not the controller's settings at the time. So the
post-mortem of a controller's run draws these marks and no analytical model.
"""

from __future__ import annotations

from dataclasses import dataclass

from shared.contract import ControllerResult, ResultSource, TighteningResult
from shared.quality import controller_result

Window = tuple[float | None, float | None]


@dataclass(frozen=True, slots=True)
class ControllerMarks:
    """The controller's windows and target of one run (None: the controller gave none)."""

    source: str  # "controller" (a bridge's live result) or "import" (a controller's file)
    torque_window_nm: Window
    angle_window_deg: Window
    torque_target_nm: float | None
    angle_target_deg: float | None
    loosening: bool = False  # the run turned the tool back

    @staticmethod
    def of(
        result: TighteningResult | None, controller: ControllerResult | None
    ) -> ControllerMarks | None:
        """The marks of a run with a controller's word (``controller``: the authority; else a
        result a controller made); None for a run boltwatch's predictor judged."""
        if controller is not None:
            source: ResultSource = (
                "import" if result and result.source == "import" else "controller"
            )
            result = controller_result(controller, None, "", source)
        elif result is None or result.source == "predictor":
            return None
        last = result.steps[-1] if result.steps else None
        function = last.function if last is not None else ""
        nominal = last.nominal if last is not None else None
        return ControllerMarks(
            source=result.source,
            torque_window_nm=(result.final_torque_nm.min, result.final_torque_nm.max),
            angle_window_deg=(result.final_angle_deg.min, result.final_angle_deg.max),
            torque_target_nm=nominal if function == "TF Torque" else None,
            angle_target_deg=nominal if function == "TF Angle" else None,
            loosening=controller is not None and controller.operation == "loosening",
        )

    def describe(self) -> str:
        """One line for the caption: the windows and target, as the controller gave them."""
        parts = [
            _window_text("torque", self.torque_window_nm, "Nm"),
            _window_text("angle", self.angle_window_deg, "deg"),
        ]
        if self.torque_target_nm is not None:
            parts.append(f"target {self.torque_target_nm:g} Nm")
        elif self.angle_target_deg is not None:
            parts.append(f"target {self.angle_target_deg:g} deg")
        else:
            parts.append("no target")
        if self.loosening:
            parts.append("a loosening: torque drawn as its magnitude")
        return ", ".join(parts)


def _window_text(figure: str, window: Window, unit: str) -> str:
    low, high = window
    if low is None and high is None:
        return f"no {figure} window"
    if low is None:
        return f"{figure} up to {high:g} {unit}"
    if high is None:
        return f"{figure} from {low:g} {unit}"
    return f"{figure} window {low:g} to {high:g} {unit}"
