"""The quality engineer's statistics per program (``boltwatch report``), as HTML and PNG.

- :mod:`.recorded_results` (the results of stations in a time range: from the results
  store, or from their recordings)
- :mod:`.quality_report` (statistics per program, the files written)
- :mod:`.report_figure` (the report's picture), :mod:`.report_page` (its HTML
  page and the lines printed)
- :mod:`.report_wear` (its tools' wear: each one's service forecast, what wears it)
"""

from shared.offline.report.quality_report import read_counts, write_report
from shared.offline.report.recorded_results import (
    RecordedResults,
    ResultFilter,
    read_results,
    read_stored,
)
from shared.offline.report.report_page import terminal_lines
from shared.offline.report.report_wear import WearPart, wear_lines

__all__ = [
    "RecordedResults",
    "ResultFilter",
    "WearPart",
    "read_counts",
    "read_results",
    "read_stored",
    "terminal_lines",
    "wear_lines",
    "write_report",
]
