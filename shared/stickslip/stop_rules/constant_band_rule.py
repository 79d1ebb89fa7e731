"""constant_out_of_band, eq. 71: the characteristic constants K1-K3 leave their band (per event).

Two bands, the model's first:

- when the station's joint is known, the median of the last n_K K_i outside
  the model's band widened by its known uncertainty: the verdict of
  :mod:`..model_bands`, passed in;
- when configured (``constant_band`` = S_i), |mean(K_i of the n_K events
  before) - K_i,now| ≥ S_i · |mean|.
"""

from __future__ import annotations

from collections import deque

from shared.stickslip.model_bands import BandVerdict
from shared.stickslip.stop_rules.stop import Stop


class ConstantBandRule:
    """Eq. 71 against the model's band and against each constant's running mean."""

    __slots__ = ("_band", "_history", "_window")

    def __init__(self, constant_band: float | None, constant_window: int) -> None:
        self._band = constant_band
        self._window = constant_window
        self._history: tuple[deque[float], deque[float], deque[float]] = (
            deque(maxlen=constant_window),
            deque(maxlen=constant_window),
            deque(maxlen=constant_window),
        )

    def check(
        self,
        constants: tuple[float | None, float | None, float | None],
        band_verdict: BandVerdict | None,
    ) -> Stop | None:
        """Event j's K1-K3 (None where not defined) and the model's verdict on them."""
        if band_verdict is not None:
            return Stop("constant_out_of_band", band_verdict.detail())
        band = self._band
        if band is None:
            return None
        for number, (history, value) in enumerate(zip(self._history, constants, strict=True), 1):
            if value is None:
                continue
            if len(history) == self._window:
                mean = sum(history) / len(history)
                if mean != 0.0 and abs(mean - value) >= band * abs(mean):
                    return Stop(
                        "constant_out_of_band",
                        f"K{number} = {value:.4g} off its running mean {mean:.4g} (eq. 71)",
                    )
            history.append(value)
        return None
