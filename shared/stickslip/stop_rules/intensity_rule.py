"""intensity_limit, eq. 70: stop when the process intensity passes I_max (checked per event)."""

from __future__ import annotations

from shared.stickslip.stop_rules.stop import Stop


class IntensityRule:
    """I_process > I_max (eq. 70); never fires without a configured I_max."""

    __slots__ = ("_limit",)

    def __init__(self, max_process_intensity: float | None) -> None:
        self._limit = max_process_intensity

    def check(self, process_intensity: float) -> Stop | None:
        limit = self._limit
        if limit is not None and process_intensity > limit:
            return Stop(
                "intensity_limit",
                f"I_process {process_intensity:.4g} > I_max {limit:.4g} (eq. 70)",
            )
        return None
