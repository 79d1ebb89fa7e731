"""(to be written)"""

from shared.offline.report.quality_report import write_report
from shared.offline.report.recorded_results import ResultFilter
from shared.offline.report.report_page import terminal_lines

__all__ = ["ResultFilter", "terminal_lines", "write_report"]
