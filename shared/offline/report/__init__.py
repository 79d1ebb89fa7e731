"""The quality engineer's statistics per program (``boltwatch report``), as HTML and PNG.

- :mod:`.recorded_results` (the results of stations in a time range: from the results
  store, or from their recordings)
- :mod:`.quality_report` (statistics per program, the files written)
- :mod:`.report_figure` (the report's picture), :mod:`.report_page` (its HTML
  page and the lines printed)
"""

from shared.offline.report.quality_report import read_counts, write_report
from shared.offline.report.recorded_results import (
    RecordedResults,
    ResultFilter,
    read_results,
    read_stored,
)
from shared.offline.report.report_page import terminal_lines

__all__ = [
    "RecordedResults",
    "ResultFilter",
    "read_counts",
    "read_results",
    "read_stored",
    "terminal_lines",
    "write_report",
]
