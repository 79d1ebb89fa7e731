"""One tightening as an Open Protocol controller keeps it: its curves and its result. Pure.

:func:`tighten` runs the rig's physics under the rig's own
:class:`~services.rig.controller.RunController` with its conventional
shutoff (a tool on Open Protocol stops itself; no StopCommand ever comes: on
the program's torque target, as a controller whose result carries no
preload does; on preload only for a program without a torque target),
one sample per millisecond, to the end of the run (settled, or aborted on a
hard limit). :class:`TighteningJudge` turns those samples into the result a
controller reports (MID 0061):

- final torque: the highest torque of the run (the peak a controller's
  shutoff reports); final angle: the angle at that sample, since the run
  started;
- the windows: the program's ``torque_min_nm`` .. ``torque_max_nm`` and
  ``angle_min_deg`` .. ``angle_max_deg``; a bound the program does not give
  is 0 (minimum) or the program's hard limit (maximum), so each figure is
  always judged low / OK / high as a controller's is; targets:
  ``target_torque_nm`` (0 when the program has none: it stops on preload),
  angle target 0 (no program has one);
- OK: torque and angle within their windows and the run not aborted. The
  preload is not judged: an Open Protocol result carries no preload (the
  station's own results judge it);
- batch: ``batch_size`` OK tightenings make a batch; the counter counts OK
  tightenings (a NOK one is not counted) and starts again at 1 after a
  complete batch; status OK when this tightening completed the batch, NOK
  (not completed) otherwise, "not used" with ``batch_size`` 0.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np
import numpy.typing as npt

from services.rig.controller import LIMITS, RunController, StopSource
from services.rig.physics import TighteningPhysics
from shared.config import Program, RigOpenProtocolSection, RigSection
from shared.model import JointConstants
from shared.quality import judge

SAMPLE_PERIOD_S = 1e-3
FigureStatus = Literal["low", "ok", "high"]
BatchStatus = Literal["nok", "ok", "not_used"]


@dataclass(frozen=True, slots=True)
class RunCurves:
    """The samples of one run at 1 kHz and how it ended."""

    torque_nm: npt.NDArray[np.float64]
    angle_deg: npt.NDArray[np.float64]
    force_n: npt.NDArray[np.float64]
    stop_source: StopSource
    slips: int

    @property
    def duration_s(self) -> float:
        return len(self.torque_nm) * SAMPLE_PERIOD_S

    @property
    def aborted(self) -> bool:
        return self.stop_source in LIMITS


@dataclass(frozen=True, slots=True)
class Tightening:
    """One tightening: the controller's result of it (MID 0061) and its curves (0900)."""

    tightening_id: int
    program_id: int
    tool_id: int
    ended_ns: int  # the controller's clock when the run ended (the result's time stamp)
    curves: RunCurves
    final_torque_nm: float
    final_angle_deg: float
    torque_min_nm: float
    torque_max_nm: float
    torque_target_nm: float
    angle_min_deg: float
    angle_max_deg: float
    angle_target_deg: float
    torque_status: FigureStatus
    angle_status: FigureStatus
    ok: bool
    batch_size: int
    batch_counter: int
    batch_status: BatchStatus
    vin: str
    # a multi-spindle system's: the spindle's channel (its number in the sync list) and the
    # cycle's sync tightening id (0: a single tool, no sync)
    channel_id: int = 1
    sync_tightening_id: int = 0

    @property
    def started_ns(self) -> int:
        return self.ended_ns - round(self.curves.duration_s * 1e9)


def tighten(
    constants: JointConstants,
    program: Program,
    rig: RigSection,
    seed: int,
    *,
    has_force_sensor: bool,
) -> RunCurves:
    """One run of the physics to its end under the tool's own shutoff and limits."""
    physics = TighteningPhysics(constants, program, rig, seed, SAMPLE_PERIOD_S)
    controller = RunController(
        physics,
        program,
        run_id=0,
        settle_time_s=rig.settle_time_s,
        has_force_sensor=has_force_sensor,
    )
    controller.start()
    rows = []
    while not controller.finished:
        measurement = controller.tick()
        rows.append((measurement.torque_nm, measurement.angle_deg, measurement.force_n))
    assert controller.stop_source is not None  # a finished run has stopped for a reason
    values = np.asarray(rows, dtype=np.float64).reshape(-1, 3)
    return RunCurves(
        torque_nm=values[:, 0].copy(),
        angle_deg=values[:, 1].copy(),
        force_n=values[:, 2].copy(),
        stop_source=controller.stop_source,
        slips=physics.slip_count,
    )


class TighteningJudge:
    """The controller's result of each run (ids counting up, the batch counter kept)."""

    def __init__(
        self,
        station_id: str,
        tool_id: int,
        settings: RigOpenProtocolSection,
        first_tightening_id: int,
    ) -> None:
        self._station_id = station_id
        self._tool_id = tool_id
        self._settings = settings
        self.next_tightening_id = first_tightening_id
        self._batch_counter = 0

    def result(self, program: Program, curves: RunCurves, ended_ns: int) -> Tightening:
        peak = int(np.argmax(curves.torque_nm))
        final_torque_nm = float(curves.torque_nm[peak])
        final_angle_deg = float(curves.angle_deg[peak])
        torque_min, torque_max = program.window("torque")
        angle_min, angle_max = program.window("angle")
        torque_window = (torque_min or 0.0, torque_max or program.max_torque_nm)
        angle_window = (angle_min or 0.0, angle_max or program.max_angle_deg)
        torque_status = _status(final_torque_nm, torque_window)
        angle_status = _status(final_angle_deg, angle_window)
        ok = not curves.aborted and torque_status == "ok" and angle_status == "ok"
        batch_size = self._settings.batch_size
        batch_status: BatchStatus = "not_used"
        if batch_size > 0:
            if self._batch_counter >= batch_size:
                self._batch_counter = 0  # the last batch was complete: a new one
            if ok:
                self._batch_counter += 1
            batch_status = "ok" if self._batch_counter == batch_size else "nok"
        tightening_id = self.next_tightening_id
        self.next_tightening_id += 1
        return Tightening(
            tightening_id=tightening_id,
            program_id=program.id,
            tool_id=self._tool_id,
            ended_ns=ended_ns,
            curves=curves,
            final_torque_nm=final_torque_nm,
            final_angle_deg=final_angle_deg,
            torque_min_nm=torque_window[0],
            torque_max_nm=torque_window[1],
            torque_target_nm=program.target_torque_nm or 0.0,
            angle_min_deg=angle_window[0],
            angle_max_deg=angle_window[1],
            angle_target_deg=0.0,
            torque_status=torque_status,
            angle_status=angle_status,
            ok=ok,
            batch_size=batch_size,
            batch_counter=self._batch_counter,
            batch_status=batch_status,
            vin=self._settings.vin(
                self._station_id, self._tool_id, tightening_id, self._batch_counter
            ),
        )


def _status(value: float, window: tuple[float, float]) -> FigureStatus:
    status = judge(value, *window).status
    assert status != "not_judged"  # a finite value against a window with both bounds
    return status
