"""What a stop rule says when it fires: the reason, a line for people, the predicted landing."""

from __future__ import annotations

from dataclasses import dataclass

from shared.contract import StopReasonName


@dataclass(frozen=True, slots=True)
class Stop:
    """A rule fired; :class:`~..stop_policy.StopPolicy` makes it the run's decision."""

    reason: StopReasonName
    detail: str
    predicted: float | None = None  # what the stop is predicted to land on (target's unit)
