"""The final stage of one run: when to slow down, when to halt, whether to pulse. Pure.

A station whose tool controller runs a program's final stage
(:class:`~shared.config.FinalStage`, ``docs/reference/can-and-trace.md``)
commands more than a stop. Why it pays, and how the rules below were chosen
and measured: ``docs/explanation/algorithm.md``, "A final stage".

Torque target (a torque-only station):

1. **Rundown.** The tool turns at the program's speed. The switch to the final
   speed (``command="final"``) comes when the torque is within
   ``switch_steps`` of the rundown's stick-ramp steps of the target: one step
   is r̂, the torque one sample of the stick ramp adds (measured between each
   slip's trough and the next peak by the halt planner; before the first one,
   k_e · φ̇_m · Δt of the joint model). A slip that drops the torque back
   below the switch point sends the tool back to the rundown speed
   (``command="rundown"``): the next stick ramp climbs at full speed.
   ``switch = "torque"``: the controller switches by itself at
   ``switch_torque_nm`` and nothing is commanded.
2. **Final.** On the slow stick ramp the torque rises by a fraction of its
   noise per sample, so the halt is decided on a line through the newest
   samples (:class:`~.sliding_line.SlidingLine`), not on one sample: the tool
   halts when the line, carried over the reaction, reaches the target. A slip
   seen in the window starts the line again.
3. **Halted.** Once the torque has been still for :data:`SETTLE_SAMPLES`
   samples (its spread within the noise) its mean is the settled torque. More
   than ``pulse_below_pct`` of the target below it (a slip during the halt
   took a drop: ``lost_drop``; or it halted short: ``short_of_target``), and
   pulses left: a pulse (``command="pulse"``) restarts the tool at the final
   speed and 2 decides its halt (``command="stop"``, with the pulse's number).
   Otherwise the run is finished (``command="finish"``): the controller ends
   it at once instead of waiting out its hold.

The run's first halt is the core's :class:`~.outputs.CoreDecision` (the
``StopDecision`` every station sends, by whichever rule made it); a pulse's
halt is a :class:`~.outputs.CoreCommand` ``stop``. Only a halt on the target
is topped up by a pulse: a run stopped by a hard limit, its intensity or its
joint's band is finished as it stands.

Force target (a station that measures preload): the tool is not slowed. The
preload rises only at a slip, and below some speed a screw that slid
smoothly comes to rest between slips: slowing it near the target turned
smoothly rising preloads into steps of several per cent, and the plateau
rules decided no better on the steps than on the ramp (measured:
``docs/explanation/algorithm.md``, "A final stage"). The run is judged once
settled and finished at once (no pulse: it would add a whole plateau step),
so the tool does not wait out its hold.
"""

from __future__ import annotations

import enum
import math
from collections import deque

from shared.config import FinalStage
from shared.contract import StageReasonName
from shared.stickslip.outputs import CoreCommand
from shared.stickslip.sliding_line import SlidingLine
from shared.stickslip.stop_rules.stop import Stop

#: samples of the line the final stage halts on (the end of a line through n noisy samples
#: has the spread 2σ/√n): tuned on the torque-only benchmark's tuning families
LINE_SAMPLES = 24
#: fewer samples than this on the line since the stage began: no halt from it yet
MIN_LINE_SAMPLES = 8
#: the torque still for this many samples in a row: settled
SETTLE_SAMPLES = 12
#: ... with its spread (max − min) within this many noise σ
SETTLE_SIGMAS = 7.0
#: after the halt decision, samples before the settle check begins (the motor halting)
SETTLE_AFTER_SAMPLES = 4
#: the longest the station waits for a settled torque after a halt before it judges anyway
MAX_SETTLE_SAMPLES = 250
#: σ of a noise estimate from the median |second difference| (white noise: 1.65 σ)
D2_PER_SIGMA = 1.65
#: a fall of this many noise σ (at least half a typical drop) below the line's highest sample
#: is a slip on the final ramp: the line starts again
SLIP_SIGMAS = 6.0
#: a predicted switch comes at least this many noise σ below the target
SWITCH_SIGMAS = 5.0


class StagePhase(enum.Enum):
    RUNDOWN = "rundown"
    FINAL = "final"
    HALTED = "halted"
    DONE = "done"


class FinalStageRun:
    """The final stage of one run, fed every sample the core uses (module docstring)."""

    def __init__(
        self,
        stage: FinalStage,
        target_nm: float | None,
        target_n: float | None,
        reaction_samples: float,
    ) -> None:
        self.stage = stage
        self.target_nm = target_nm  # torque target (None: a force target decides)
        self.force_mode = target_n is not None
        self.phase = StagePhase.RUNDOWN
        self.pulses = 0
        self.switched_at_s: float | None = None  # when the final stage began (run seconds)
        self._lead = reaction_samples + 0.5
        self._skip = math.ceil(reaction_samples) + 1  # samples before a command takes effect
        self._line = SlidingLine(LINE_SAMPLES)
        self._line_max = -math.inf
        self._skipping = 0
        self._pulses_allowed = False
        self._since_halt = 0
        self._still: deque[float] = deque(maxlen=SETTLE_SAMPLES)
        self._switch_nm = math.nan  # the predicted switch point
        self._rundown_step_nm = math.nan  # r̂ when the stage first switched (rundown speed)
        self._rundown_line = SlidingLine(LINE_SAMPLES)  # the rise when no step is known

    # -- what the core tells it ---------------------------------------------------------

    def on_decided(self, reason: str) -> None:
        """The run's first halt was decided (by any rule): wait for it to settle.

        Only a halt on the target is topped up by pulses (torque target)."""
        if self.phase in (StagePhase.HALTED, StagePhase.DONE):
            return
        self._halted(pulses_allowed=reason == "target_reached" and not self.force_mode)

    def on_tool_halted(self) -> None:
        """The tool halted by itself (its own shutoff at the target) before any decision."""
        if self.phase in (StagePhase.RUNDOWN, StagePhase.FINAL):
            self._halted(pulses_allowed=not self.force_mode)

    # -- every sample ---------------------------------------------------------------------

    def on_sample(
        self,
        time_s: float,
        torque_nm: float,
        rundown_step_nm: float,
        noise_sigma_nm: float,
        drop_nm: float,
    ) -> CoreCommand | Stop | None:
        """One sample the core used; a command for the tool, the first halt's Stop, or None.

        ``rundown_step_nm``: r̂, the stick ramp's rise per sample at the rundown speed
        (NaN: unknown, then the line through the rundown's newest samples gives it; once
        the stage has switched, the r̂ of that moment holds: later ramps ran slower);
        ``noise_sigma_nm``: the torque's noise; ``drop_nm``: a typical slip's torque drop
        (NaN: none seen yet).
        """
        phase = self.phase
        if phase is StagePhase.RUNDOWN:
            return self._rundown(time_s, torque_nm, rundown_step_nm, noise_sigma_nm)
        if phase is StagePhase.FINAL:
            return self._final(time_s, torque_nm, noise_sigma_nm, drop_nm)
        if phase is StagePhase.HALTED:
            return self._settling(time_s, torque_nm, noise_sigma_nm, drop_nm)
        return None

    def _rundown(
        self, time_s: float, torque_nm: float, step_nm: float, sigma_nm: float
    ) -> CoreCommand | None:
        target = self.target_nm
        if target is None:  # a force target: the tool is not slowed (module docstring)
            return None
        stage = self.stage
        if stage.switch == "torque":
            assert stage.switch_torque_nm is not None
            if torque_nm >= stage.switch_torque_nm:  # the controller switches by itself
                self._enter_final(time_s)
            return None
        line = self._rundown_line
        line.add(torque_nm)
        if self._rundown_step_nm > 0.0:
            # back in the rundown after a slip: the ramps measured since ran at the final
            # speed, the step of the rundown is the one measured before the first switch
            step_nm = self._rundown_step_nm
        elif not step_nm > 0.0:
            step_nm = line.slope if len(line) >= MIN_LINE_SAMPLES else math.nan
        if not step_nm > 0.0:
            return None
        # before a noisy sample can reach the target (the tool's own shutoff watches
        # single samples at the rundown speed)
        switch_nm = target - max(stage.switch_steps * step_nm, SWITCH_SIGMAS * sigma_nm)
        if torque_nm < switch_nm:
            return None
        self._switch_nm = switch_nm
        self._rundown_step_nm = step_nm
        return self._switch(
            time_s,
            torque_nm,
            f"torque {torque_nm:.5g} Nm within {target - switch_nm:.3g} Nm of target "
            f"{target:g} Nm ({stage.switch_steps:g} rundown ramp steps of {step_nm:.3g} Nm, "
            f"or {SWITCH_SIGMAS:g} σ of noise)",
        )

    def _switch(self, time_s: float, torque_nm: float, detail: str) -> CoreCommand:
        self._enter_final(time_s)
        return CoreCommand(time_s, "final", "near_target", detail, torque_nm)

    def _enter_final(self, time_s: float) -> None:
        self.phase = StagePhase.FINAL
        if self.switched_at_s is None:
            self.switched_at_s = time_s
        self._restart_line()

    def _restart_line(self) -> None:
        self._line.clear()
        self._line_max = -math.inf
        self._skipping = self._skip

    def _final(
        self, time_s: float, torque_nm: float, sigma_nm: float, drop_nm: float
    ) -> CoreCommand | Stop | None:
        if self._skipping > 0:  # the command has not taken effect yet
            self._skipping -= 1
            return None
        target = self.target_nm
        assert target is not None  # a force target never switches
        slip_nm = max(SLIP_SIGMAS * sigma_nm, 0.5 * drop_nm if drop_nm > 0.0 else 0.0)
        if torque_nm < self._line_max - slip_nm:
            # a slip on the final ramp: the line held for the phase before it
            self._restart_line()
            self._skipping = 0
            if (
                self.stage.switch == "predicted"
                and self.pulses == 0
                and torque_nm < self._switch_nm - 2.0 * self._rundown_step_nm
            ):
                self.phase = StagePhase.RUNDOWN
                return CoreCommand(
                    time_s,
                    "rundown",
                    "below_switch_point",
                    f"a slip dropped the torque to {torque_nm:.5g} Nm, below the switch point "
                    f"{self._switch_nm:.5g} Nm",
                    torque_nm,
                )
        line = self._line
        line.add(torque_nm)
        self._line_max = max(self._line_max, torque_nm)
        if len(line) < MIN_LINE_SAMPLES:
            return None
        slope = line.slope
        end = line.end
        at_halt = end + max(slope, 0.0) * self._lead
        if at_halt < target:
            return None
        detail = (
            f"final stage: torque line {end:.5g} Nm rising {slope:.3g} Nm a sample, "
            f"{at_halt:.5g} Nm at the halt ≥ target {target:g} Nm"
        )
        if self.pulses == 0:
            return Stop("target_reached", detail, at_halt)  # the run's first halt (latched)
        self._halted(pulses_allowed=True)
        return CoreCommand(time_s, "stop", "target_reached", detail, torque_nm, self.pulses)

    def _halted(self, pulses_allowed: bool) -> None:
        self.phase = StagePhase.HALTED
        self._pulses_allowed = pulses_allowed
        self._since_halt = 0
        self._still.clear()

    def _settling(
        self, time_s: float, torque_nm: float, sigma_nm: float, drop_nm: float
    ) -> CoreCommand | None:
        self._since_halt += 1
        if self._since_halt <= SETTLE_AFTER_SAMPLES:
            return None
        still = self._still
        still.append(torque_nm)
        if len(still) < SETTLE_SAMPLES:
            return None
        spread = max(still) - min(still)
        waited_out = self._since_halt >= MAX_SETTLE_SAMPLES
        if spread > SETTLE_SIGMAS * sigma_nm and not waited_out:
            return None
        settled_nm = sum(still) / len(still)
        how = "settled" if not waited_out else f"not still after {self._since_halt} samples"
        return self._after_halt(time_s, settled_nm, drop_nm, how)

    def _after_halt(
        self, time_s: float, settled_nm: float, drop_nm: float, how: str
    ) -> CoreCommand:
        stage = self.stage
        target = self.target_nm
        short_nm = (target - settled_nm) if target is not None else math.nan
        wanted = target is not None and short_nm > 0.01 * stage.pulse_below_pct * target
        if wanted and self._pulses_allowed and self.pulses < stage.max_pulses:
            assert target is not None
            self.pulses += 1
            lost = drop_nm > 0.0 and short_nm >= 0.5 * drop_nm
            self.phase = StagePhase.FINAL
            self._restart_line()
            return CoreCommand(
                time_s,
                "pulse",
                "lost_drop" if lost else "short_of_target",
                f"{how} at {settled_nm:.5g} Nm, {100.0 * short_nm / target:.2f} % below "
                f"target {target:g} Nm" + (f" (a slip drop is {drop_nm:.3g} Nm)" if lost else ""),
                settled_nm,
                self.pulses,
            )
        self.phase = StagePhase.DONE
        reason: StageReasonName = (
            "pulses_exhausted" if wanted and self._pulses_allowed else "settled"
        )
        where = f"{how} at {settled_nm:.5g} Nm"
        if target is not None:
            where += f" ({100.0 * (settled_nm - target) / target:+.2f} % of target {target:g} Nm)"
        if not self._pulses_allowed and wanted:
            where += ": no pulse after a stop that was not on the target"
        return CoreCommand(time_s, "finish", reason, where, settled_nm, self.pulses)
