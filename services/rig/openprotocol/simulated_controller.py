"""The rig as an Open Protocol controller: the tool on its own pace, the TCP server, joined.

:class:`SimulatedController` listens from construction (so a port in use is
an error at start) and :meth:`~SimulatedController.run` serves in the
calling thread while the tool tightens in its own thread. With ``runs`` the
tool stops after that many tightenings and the controller stays until an
integrator has had every tightening it keeps (acknowledged its 0061, or was
served its 0065: one that was away while the tool tightened fetches them when
it is back, however late), every result pushed is acknowledged (or its link
dropped) and nothing has been outstanding for :data:`LINGER_S`; then ``run``
returns. Without ``runs`` it serves until ``stop``. A station of several spindles
(``[station] spindles``) is a multi-spindle system: ``runs`` counts its cycles,
each a tightening of every spindle, then the cycle's 0091 and 0101.
"""

from __future__ import annotations

import logging
import threading
import time

from services.rig.openprotocol.controller_server import ControllerServer
from services.rig.openprotocol.controller_state import ControllerState
from services.rig.openprotocol.simulated_tool import SimulatedTool
from services.rig.openprotocol.tightening import Tightening, TighteningJudge
from services.rig.openprotocol.tightening_counter import TighteningCounter
from shared.config import LoadedStation, Program
from shared.errors import ConfigError
from shared.model import JointConstants

LOG = logging.getLogger(__name__)

#: after the last run, how long nothing may be outstanding before the controller ends
LINGER_S = 2.0
#: a tightening id is 10 digits in MID 0061
TIGHTENING_ID_MAX = 9_999_999_999


class SimulatedController:
    """One station's simulated controller (``serve rig --controller openprotocol``)."""

    def __init__(
        self,
        station: LoadedStation,
        program: Program,
        *,
        first_tightening_id: int,
        seed: int,
        runs: int | None = None,
        wait_for_integrator: bool = False,
        counter: TighteningCounter | None = None,
    ) -> None:
        """``counter``: where the last tightening id is kept across restarts (none: nowhere)."""
        config = station.config
        section = config.openprotocol
        if section is None:
            raise ConfigError(
                f"{station.path}: openprotocol: the section is needed by --controller "
                "openprotocol (host and port the controller listens on)"
            )
        spindles = config.station.spindles
        last_id = first_tightening_id + (runs or 1) * spindles - 1
        if first_tightening_id < 1 or last_id > TIGHTENING_ID_MAX:
            raise ConfigError(
                f"--first-run-id must keep tightening ids within 1..{TIGHTENING_ID_MAX} "
                "(10 digits in MID 0061)"
            )
        self.runs = runs
        self.seed = seed
        self.state = ControllerState(
            config.station.id,
            config.station.tool_id,
            program,
            section,
            config.rig.openprotocol,
            spindles=spindles,
        )
        self.server = ControllerServer(section.host, section.port, self.state)
        judge = TighteningJudge(
            config.station.id, config.station.tool_id, config.rig.openprotocol, first_tightening_id
        )
        self.tool = SimulatedTool(
            JointConstants.of(station.joint_of(program.id)),
            program,
            config.rig,
            judge,
            # a controller on Open Protocol tightens to torque (0061 carries no preload): its
            # shutoff is the program's torque target; on preload only for a program without one
            has_force_sensor=config.station.has_force_sensor and program.target_torque_nm is None,
            on_tightening=self._tightened,
            spindles=spindles,
            on_cycle=self.server.report_cycle,
        )
        self._wait_for_integrator = wait_for_integrator
        self._counter = counter
        self._tool_done = threading.Event()
        self._quiet_since: float | None = None

    def close(self) -> None:
        self.server.close()

    def run(self, stop: threading.Event) -> None:
        """Serve and tighten until ``stop`` (or, with ``runs``, until all is delivered)."""
        tool = threading.Thread(target=self._tighten, args=(stop,), name="tool", daemon=True)
        tool.start()
        try:
            self.server.serve(stop, until=self._delivered)
        finally:
            stop.set()
            tool.join()
            LOG.info("controller ends: %s", self.state.counters.line())

    def _tighten(self, stop: threading.Event) -> None:
        try:
            start = self.state.result_subscriber if self._wait_for_integrator else None
            self.tool.run(self.seed, stop, self.runs, start)
        finally:
            self._tool_done.set()

    def _tightened(self, tightening: Tightening) -> None:
        if self._counter is not None:
            self._counter.keep(tightening.tightening_id)
        self.server.report(tightening)

    def _delivered(self) -> bool:
        """With ``runs``: the tool is done, an integrator has had every kept tightening, and
        nothing was outstanding for LINGER_S."""
        if self.runs is None or not self._tool_done.is_set():
            return False
        if self.server.outstanding or self.state.undelivered():
            self._quiet_since = None
            return False
        now = time.monotonic()
        if self._quiet_since is None:
            self._quiet_since = now
        return now - self._quiet_since >= LINGER_S
