"""Post-mortem: the paper's figures of one recorded run (``boltwatch inspect``), and the run
as data for the line's page.

- :mod:`.post_mortem_run`: a run read back from its recording (one file, or its parts)
- :mod:`.post_mortem_errors`: prediction errors (eqs. 61-63)
- :mod:`.post_mortem_panels`: the panels of Figures 10, 13-15, 22, 23
- :mod:`.run_plot`: the figure drawn and saved
- :mod:`.curve_points`: which samples of a curve a browser is sent, as JSON columns
- :mod:`.run_document`: the run as plain data for a browser to draw (the line's page)
"""

from shared.offline.post_mortem.curve_points import MAX_POINTS, drawn_indices, json_column
from shared.offline.post_mortem.post_mortem_errors import prediction_errors
from shared.offline.post_mortem.post_mortem_panels import plateau_bars
from shared.offline.post_mortem.post_mortem_run import RecordedRun, read_run, read_run_files
from shared.offline.post_mortem.run_document import run_document
from shared.offline.post_mortem.run_plot import build_figure, draw_run

__all__ = [
    "MAX_POINTS",
    "RecordedRun",
    "build_figure",
    "draw_run",
    "drawn_indices",
    "json_column",
    "plateau_bars",
    "prediction_errors",
    "read_run",
    "read_run_files",
    "run_document",
]
