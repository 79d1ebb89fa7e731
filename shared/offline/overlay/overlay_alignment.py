"""Where the runs of an overlay are aligned: ``start``, ``torque:NM`` or ``first-slip``.

- ``start``: the run's first sample;
- ``torque:NM``: the first sample whose torque reaches NM newton-metres;
- ``first-slip``: the sample of the run's first stick-slip event (its torque
  peak, the ``events`` channel), found by its receive time.

:func:`align_index` gives the sample a run is aligned at, or None when the
run never reaches that point (the overlay then says which run and what it
never reached).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np

from shared.errors import InputError
from shared.offline.overlay.overlay_run import OverlayRun

AlignmentKind = Literal["start", "torque", "first-slip"]


@dataclass(frozen=True, slots=True)
class Alignment:
    kind: AlignmentKind
    torque_nm: float = 0.0  # the threshold of ``torque``

    def describe(self) -> str:
        if self.kind == "torque":
            return f"torque first reaches {self.torque_nm:g} Nm"
        return "first stick-slip event" if self.kind == "first-slip" else "start of run"

    def missing(self) -> str:
        """What a run that has no such point never does."""
        if self.kind == "torque":
            return f"never reaches {self.torque_nm:g} Nm"
        return "has no stick-slip event" if self.kind == "first-slip" else "has no samples"


def parse_alignment(text: str) -> Alignment:
    """``start``, ``first-slip`` or ``torque:NM`` (NM a finite number > 0)."""
    if text in ("start", "first-slip"):
        return Alignment(text)  # type: ignore[arg-type]
    kind, _, value = text.partition(":")
    if kind == "torque":
        try:
            torque_nm = float(value)
        except ValueError:
            torque_nm = math.nan
        if math.isfinite(torque_nm) and torque_nm > 0.0:
            return Alignment("torque", torque_nm)
    raise InputError(
        f"--align {text!r}: expected start, first-slip or torque:NM "
        "(NM the torque in Nm, a number above 0, e.g. torque:150)"
    )


def align_index(run: OverlayRun, alignment: Alignment) -> int | None:
    """The index of the sample ``run`` is aligned at; None when it never gets there."""
    if len(run.time_s) == 0:
        return None
    if alignment.kind == "start":
        return 0
    if alignment.kind == "torque":
        reached = np.flatnonzero(run.torque_nm >= alignment.torque_nm)
        return int(reached[0]) if len(reached) else None
    if not run.events:
        return None
    # the event's peak sample: the one received at the event's time (else the nearest); of
    # samples received at one time (a burst of frames), the one with the peak's torque
    event = run.events[0]
    distance_ns = np.abs(run.time_ns - event.time_ns)
    nearest = np.flatnonzero(distance_ns == distance_ns.min())
    return int(nearest[np.argmin(np.abs(run.torque_nm[nearest] - event.peak_torque_nm))])
