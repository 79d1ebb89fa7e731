"""(to be written)"""

from shared.quality.capability import capability, window_text
from shared.quality.control_chart import c4, control_chart
from shared.quality.controller_result import controller_result
from shared.quality.program_statistics import (
    FigureStatistics,
    ProgramStatistics,
    program_statistics,
)
from shared.quality.run_result import tightening_result
from shared.quality.verdict import cut_text, judge

__all__ = [
    "FigureStatistics",
    "ProgramStatistics",
    "c4",
    "capability",
    "control_chart",
    "controller_result",
    "cut_text",
    "judge",
    "program_statistics",
    "tightening_result",
    "window_text",
]
