"""What may decide on the acquisition's own CAN thread: the stop path of one sample.

A station whose predictor runs on its edge box (the default:
``docs/explanation/decisions/0001-edge-stop-decision.md``) hands the
acquisition a :class:`Decider`. Each sample goes to it on the CAN thread as
soon as it is complete, and a decision goes out as a ``StopCommand`` from that
same thread: CAN in, CAN out, no process
or network between them. The acquisition defines this protocol and the
predictor implements it (``services/predictor/edge_predictor.py``); the CLI
joins the two (services never import each other).

Both calls run on the CAN thread between two frames: they must not wait
(no blocking I/O, no lock another thread holds for long). What they publish
goes through a queue (:mod:`shared.runtime.queued_publisher`).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Protocol

from shared.config import LoadedStation
from shared.contract import Sample, StageDecision, StopDecision, ToolState
from shared.runtime import ServiceSkeleton


class Decider(Protocol):
    """Follows the station's runs; decides when to stop the tool."""

    def on_tool_state(self, state: ToolState) -> None:
        """The tool's run state changed (``done`` / ``aborted`` say what stopped it)."""

    def on_sample(self, sample: Sample) -> StopDecision | StageDecision | None:
        """A complete sample of the running run; a decision to stop the tool now, a final
        stage's command (a tool that runs one), or None."""


class StationDecider(Decider, Protocol):
    """A decider that lives as long as the acquisition's session (its health token is
    declared through the acquisition's skeleton)."""

    def close(self) -> None:
        """Stop what runs beside the CAN thread (the WORK stage of the acquisition's stop)."""


#: (the acquisition's skeleton, the station, a publish that never waits) -> the station's
#: decider; the CLI passes the predictor's EdgePredictor (services never import each other)
DeciderFactory = Callable[
    [ServiceSkeleton, LoadedStation, Callable[[object], None]], StationDecider
]
