"""What a multi-spindle station says of one synchronised cycle: the part's common result.

A multi-spindle system (a fixtured nutrunner with 2 to 20 spindles: wheels,
cylinder heads, axles) tightens several bolts of one part in one
synchronised cycle. Each spindle's tightening is a run of its own, with its
own run id, curve, result and summary, as a single-spindle station's run is;
what ties them is the cycle's **sync id** (the controller's id of the cycle,
:attr:`ToolState.sync_id <shared.contract.messages.ToolState.sync_id>` and the
same field of the run's summary and result) and each run's **spindle**
number (1 to N). A single-spindle station says neither (both None), and its
messages read as before.

:class:`CycleResult` is the cycle's common result, made where the last
spindle's result is known (the station's predictor; a controller bridge from
the controller's multi-spindle result, Open Protocol MID 0101), on
``boltwatch/<st>/cycles``: OK only when every spindle of the cycle is OK; a
spindle whose result never came makes it NOK. Same rules as every message
(:mod:`shared.contract.messages`).
"""

from __future__ import annotations

from dataclasses import dataclass, field

from shared.contract.message_fields import WIRE_CONFIG, Id, PartId, SpindleNumber, StationId, TimeNs
from shared.contract.messages import ResultSource, Verdict


@dataclass(frozen=True, slots=True)
class CycleSpindle:
    """One spindle of a cycle: its run and that run's verdict."""

    __pydantic_config__ = WIRE_CONFIG

    spindle: SpindleNumber
    # its run (its TighteningResult); None: no result of it came (or, a controller's cycle,
    # its tightening was not published: the controller's verdict of it is kept)
    run_id: Id | None
    result: Verdict | None  # None: no result came (the cycle is NOK)


@dataclass(frozen=True, slots=True)
class CycleResult:
    """The common result of one multi-spindle cycle: OK only when every spindle is OK."""

    __pydantic_config__ = WIRE_CONFIG

    station: StationId
    sync_id: Id  # the controller's id of the cycle, in each spindle's run
    time_ns: TimeNs  # when its last spindle's run ended
    part_id: PartId | None  # the part the cycle tightened; None: unknown
    program_id: Id
    result: Verdict
    nok_reasons: str  # why NOK ("spindle 3 NOK; spindle 4 no result"); "" when OK
    source: ResultSource
    # every spindle of the cycle, in spindle order (a spindle with no result: run_id None)
    spindles: list[CycleSpindle] = field(default_factory=list)

    @property
    def run_ids(self) -> list[int]:
        """The runs of the cycle whose results came, in spindle order."""
        return [s.run_id for s in self.spindles if s.run_id is not None]
