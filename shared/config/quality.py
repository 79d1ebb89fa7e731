"""The ``[quality]`` section of a station file: when the recorder raises a quality alert.

Per (station, program) the recorder keeps the last ``window_runs`` results
(:mod:`services.recorder.quality_watch`) and alerts when

- the rolling Cpk of a figure (torque, angle, preload) against the newest
  result's window falls below ``cpk_min`` (no Cpk before ``min_runs`` results
  with that figure: fewer say nothing about a process);
- ``nok_run`` results in a row are NOK;
- ``nok_max`` or more of the last ``nok_window`` results are NOK.
"""

from __future__ import annotations

from pydantic import Field, model_validator

from shared.config.loading import StrictModel


class QualitySection(StrictModel):
    cpk_min: float = Field(default=1.33, gt=0, description="a rolling Cpk below it alerts")
    window_runs: int = Field(
        default=50, ge=2, le=10_000, description="results per program the Cpk is computed over"
    )
    min_runs: int = Field(default=20, ge=2, description="no Cpk before this many results")
    nok_run: int = Field(default=3, ge=1, le=10_000, description="NOKs in a row that alert")
    nok_window: int = Field(default=20, ge=1, le=10_000, description="the last N results ...")
    nok_max: int = Field(default=5, ge=1, description="... of which this many NOK alert")

    @model_validator(mode="after")
    def _consistent(self) -> QualitySection:
        if self.min_runs > self.window_runs:
            raise ValueError(
                f"min_runs ({self.min_runs}) must not exceed window_runs ({self.window_runs})"
            )
        if self.nok_max > self.nok_window:
            raise ValueError(
                f"nok_max ({self.nok_max}) must not exceed nok_window ({self.nok_window})"
            )
        return self
