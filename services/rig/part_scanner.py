"""The line's part scanner, simulated: each part's id on zenoh before its first run.

A tool on CAN does not know which part it tightens; on a line, the PLC (or
a scanner at the station) says so when a part arrives. The rig stands in for
it: every ``[rig] bolts_per_part`` runs a new part arrives, and before the
part's first run (and the rig's pause before it) the scanner puts a
:class:`~shared.contract.PartScan` on ``boltwatch/<st>/part`` with the part's
id (``[rig] part_pattern``: by default ``<station>-P<the run id of its first
bolt>``). The station's predictor names that part in the result of each run
that starts after it. A multi-spindle system (``[station] spindles`` above 1)
tightens a part in each synchronised cycle: a part per cycle, its bolts the
cycle's spindles.

The rig's first part waits (at most :data:`LISTENER_WAIT_S`) until a
subscriber of the key is known (the station's predictor, the recorder):
a part put before anyone listens would be lost, and its runs would name no
part. :func:`starts_part` (which runs start a part) is pure.
"""

from __future__ import annotations

import logging
import time
from collections.abc import Callable
from typing import Any

import zenoh

from shared.config import RigSection
from shared.contract import PartScan, channels, codec
from shared.runtime import ServiceSkeleton

LOG = logging.getLogger(__name__)

#: how long the first part waits for a subscriber of the part key
LISTENER_WAIT_S = 2.0
_POLL_S = 0.02


def starts_part(index: int, bolts_per_part: int) -> bool:
    """Whether run ``index`` (from 0, since the rig started) is the first bolt of a part (0
    bolts per part: the rig announces no part)."""
    return bolts_per_part > 0 and index % bolts_per_part == 0


class PartScanner:
    """Puts the part of each run that starts one (the rig's ``PartSource``)."""

    def __init__(
        self,
        skeleton: ServiceSkeleton,
        station: str,
        rig: RigSection,
        clock_ns: Callable[[], int] = time.time_ns,
        per_cycle_of: int = 1,
    ) -> None:
        """``per_cycle_of``: a multi-spindle system of that many spindles (above 1) tightens a
        part in each cycle: each of its cycles starts a part (``before_run`` is told cycles)."""
        self._station = station
        self._per_cycle_of = per_cycle_of
        self._rig = rig
        self._clock_ns = clock_ns
        self._publisher = skeleton.publisher(channels.PART, station)
        self.parts = 0  # parts put since the start

    def before_run(self, index: int, run_id: int) -> bool:
        """Before run ``index`` (from 0; run id ``run_id``) and its pause: True when the run
        starts a new part, whose scan was put."""
        bolts = self._rig.bolts_per_part
        if self._per_cycle_of > 1:  # ``index`` counts cycles: each is a part of its own
            index *= self._per_cycle_of
            bolts = self._per_cycle_of if bolts > 0 else 0
        if not starts_part(index, bolts):
            return False
        if self.parts == 0:
            self._wait_for_listener()
        scan = PartScan(self._station, self._rig.part_id(self._station, run_id), self._clock_ns())
        self._publisher.put(codec.encode(scan))
        self.parts += 1
        LOG.info("part %s at the station: runs %d to %d", scan.part_id, run_id, run_id + bolts - 1)
        return True

    def _wait_for_listener(self) -> None:
        deadline = time.monotonic() + LISTENER_WAIT_S
        while not _has_subscribers(self._publisher):
            if time.monotonic() > deadline:
                LOG.warning(
                    "no subscriber of %s after %.0f s: the first part is put anyway",
                    channels.PART.key(self._station),
                    LISTENER_WAIT_S,
                )
                return
            time.sleep(_POLL_S)


def _has_subscribers(publisher: zenoh.Publisher) -> bool:
    """zenoh 1.10's stubs type ``matching_status`` as bool; it is a MatchingStatus."""
    status: Any = publisher.matching_status
    return bool(getattr(status, "matching", status))
