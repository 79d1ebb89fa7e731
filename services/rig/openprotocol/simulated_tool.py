"""The tool on its own pace: one tightening after another, whether or not anyone listens.

A tool on a line tightens when the operator pulls the trigger, not when an
integrator is connected. Each run is computed at once by the physics
(:func:`~services.rig.openprotocol.tightening.tighten`, about 10 ms for a
run of 1.7 s), then the tool waits until the run's own duration has passed
on the wall clock (1 ms a sample) before the controller reports it, then
pauses ``pause_between_runs_s`` before the next. A stop during a run ends it
unreported (the tool was switched off in the middle of a joint).

Seeds: run k (0-based) uses ``seed + k``, as the CAN rig's runs do.
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable

from services.rig.openprotocol.tightening import Tightening, TighteningJudge, tighten
from shared.config import Program, RigSection
from shared.model import JointConstants

LOG = logging.getLogger(__name__)


class SimulatedTool:
    """Runs tightenings of ``program`` and hands each finished one to ``on_tightening``."""

    def __init__(
        self,
        constants: JointConstants,
        program: Program,
        rig: RigSection,
        judge: TighteningJudge,
        *,
        has_force_sensor: bool,
        on_tightening: Callable[[Tightening], None],
        wall_clock_ns: Callable[[], int] = time.time_ns,
    ) -> None:
        self._constants = constants
        self._program = program
        self._rig = rig
        self._judge = judge
        self._has_force_sensor = has_force_sensor
        self._on_tightening = on_tightening
        self._wall_clock_ns = wall_clock_ns
        self.tightenings = 0

    def run(
        self,
        seed: int,
        stop: threading.Event,
        runs: int | None = None,
        start: threading.Event | None = None,
    ) -> int:
        """Tighten ``runs`` joints (None: until ``stop``); returns how many were reported.

        ``start``: the first run waits for it (an operator waiting for the line to be
        ready); the runs after keep the tool's own pace, listened to or not.
        """
        if start is not None:
            while not start.wait(0.05):
                if stop.is_set():
                    return 0
        index = 0
        while not stop.is_set() and (runs is None or index < runs):
            if index > 0 and stop.wait(self._rig.pause_between_runs_s):
                break
            started = time.monotonic()
            curves = tighten(
                self._constants,
                self._program,
                self._rig,
                seed + index,
                has_force_sensor=self._has_force_sensor,
            )
            if stop.wait(max(0.0, started + curves.duration_s - time.monotonic())):
                LOG.info("stopped in the middle of a run: not reported")
                break
            tightening = self._judge.result(self._program, curves, self._wall_clock_ns())
            self.tightenings += 1
            self._on_tightening(tightening)
            index += 1
        return self.tightenings
