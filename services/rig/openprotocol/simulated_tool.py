"""The tool on its own pace: one tightening after another, whether or not anyone listens.

A tool on a line tightens when the operator pulls the trigger, not when an
integrator is connected. Each run is computed at once by the physics
(:func:`~services.rig.openprotocol.tightening.tighten`, about 10 ms for a
run of 1.7 s), then the tool waits until the run's own duration has passed
on the wall clock (1 ms a sample) before the controller reports it, then
pauses ``pause_between_runs_s`` before the next. A stop during a run ends it
unreported (the tool was switched off in the middle of a joint).

Seeds: run k (0-based) uses ``seed + k``, as the CAN rig's runs do.

A multi-spindle system (``spindles`` above 1) runs cycles: in cycle c every
spindle k (1..N) tightens its own joint (seed ``seed + c * N + k - 1``) at
once; the cycle lasts as long as its longest run (a spindle that ends early
waits for the others), then each spindle's tightening is reported (channel k,
the cycle's sync tightening id: its first tightening id, within 1..65535; the
part's VIN: its first spindle's), and the cycle (``on_cycle``). ``runs`` counts
cycles.
"""

from __future__ import annotations

import dataclasses
import logging
import threading
import time
from collections.abc import Callable

from services.rig.openprotocol.tightening import RunCurves, Tightening, TighteningJudge, tighten
from shared.config import Program, RigSection
from shared.model import JointConstants

LOG = logging.getLogger(__name__)

#: the highest sync tightening id (five digits, 0091 and 0101 say 65535)
SYNC_ID_MAX = 65535


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
        spindles: int = 1,
        on_cycle: Callable[[list[Tightening]], None] | None = None,
    ) -> None:
        self._constants = constants
        self._program = program
        self._rig = rig
        self._judge = judge
        self._has_force_sensor = has_force_sensor
        self._on_tightening = on_tightening
        self._wall_clock_ns = wall_clock_ns
        self._spindles = spindles
        self._on_cycle = on_cycle
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
        spindles = self._spindles
        while not stop.is_set() and (runs is None or index < runs):
            if index > 0 and stop.wait(self._rig.pause_between_runs_s):
                break
            started = time.monotonic()
            curves = [
                tighten(
                    self._constants,
                    self._program,
                    self._rig,
                    seed + index * spindles + k,
                    has_force_sensor=self._has_force_sensor,
                )
                for k in range(spindles)
            ]
            longest_s = max(c.duration_s for c in curves)
            if stop.wait(max(0.0, started + longest_s - time.monotonic())):
                LOG.info("stopped in the middle of a run: not reported")
                break
            ended_ns = self._wall_clock_ns()
            if spindles == 1:
                tightening = self._judge.result(self._program, curves[0], ended_ns)
                self.tightenings += 1
                self._on_tightening(tightening)
            else:
                self._report_cycle(curves, ended_ns)
            index += 1
        return self.tightenings

    def _report_cycle(self, curves: list[RunCurves], ended_ns: int) -> None:
        """Each spindle's tightening of the cycle just ended (its channel, the cycle's sync
        id), then the cycle."""
        sync_id = (self._judge.next_tightening_id - 1) % SYNC_ID_MAX + 1
        cycle: list[Tightening] = []
        for channel, spindle_curves in enumerate(curves, start=1):
            tightening = dataclasses.replace(
                self._judge.result(self._program, spindle_curves, ended_ns),
                channel_id=channel,
                sync_tightening_id=sync_id,
            )
            if cycle:  # one part a cycle: its first spindle's
                tightening = dataclasses.replace(tightening, vin=cycle[0].vin)
            cycle.append(tightening)
            self.tightenings += 1
            self._on_tightening(tightening)
        if self._on_cycle is not None:
            self._on_cycle(cycle)
