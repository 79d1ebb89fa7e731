"""The quality engineer's statistics per program (``boltwatch report``), as HTML and PNG.

- :mod:`.recorded_results` (the results of a station's recordings in a time range)
- :mod:`.quality_report` (results read, statistics per program, the files written)
- :mod:`.report_figure` (the report's picture), :mod:`.report_page` (its HTML
  page and the lines printed)
"""

from shared.offline.report.quality_report import write_report
from shared.offline.report.recorded_results import ResultFilter
from shared.offline.report.report_page import terminal_lines

__all__ = ["ResultFilter", "terminal_lines", "write_report"]
