"""OK or NOK, and how capable a program is: the verdict, results, Cpk and control charts. Pure.

- :mod:`.verdict` (each final figure against its window, then the verdict: where
  OK/NOK is decided)
- :mod:`.run_result` (a live run's TighteningResult from its summary and
  program), :mod:`.controller_result` (a controller's run's, from its own values),
  :mod:`.cycle_result` (a multi-spindle cycle's common result from its spindles')
- :mod:`.capability` (mean, σ, Cp and Cpk of one figure against its window),
  :mod:`.control_chart` (Shewhart X̄/R and X̄/s), :mod:`.program_columns`
  (what a program's statistics are made from, as columns), :mod:`.program_statistics`
  (a program's statistics over its columns), :mod:`.plausible_result` (whether a
  result's figures can be a measurement at all: what statistics refuse)
"""

from shared.quality.capability import capability, window_text
from shared.quality.control_chart import c4, control_chart
from shared.quality.controller_result import SAID_OK_WINDOWS_NOK, Window, controller_result
from shared.quality.cycle_result import CycleTally, cycle_result
from shared.quality.plausible_result import figures_fault, implausible, refusal_line
from shared.quality.program_columns import ProgramColumns, columns_of
from shared.quality.program_statistics import (
    FigureStatistics,
    ProgramStatistics,
    program_statistics,
    statistics_of,
)
from shared.quality.run_result import tightening_result
from shared.quality.verdict import cut_text, judge

__all__ = [
    "SAID_OK_WINDOWS_NOK",
    "CycleTally",
    "FigureStatistics",
    "ProgramColumns",
    "ProgramStatistics",
    "Window",
    "c4",
    "capability",
    "columns_of",
    "control_chart",
    "controller_result",
    "cut_text",
    "cycle_result",
    "figures_fault",
    "implausible",
    "judge",
    "program_statistics",
    "refusal_line",
    "statistics_of",
    "tightening_result",
    "window_text",
]
