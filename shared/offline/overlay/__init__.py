"""Overlay: several recorded runs on one figure (``boltwatch inspect --overlay``), and side by
side on the line's page.

- :mod:`.overlay_run`: one run read back (samples, events, result), found by id or path;
  a multi-spindle cycle's runs
- :mod:`.overlay_alignment`: where runs are aligned (start, a torque, the first slip)
- :mod:`.overlay_series`: the plotted series, aligned, and the programs' windows (data only)
- :mod:`.overlay_plot`: the figure drawn and saved (matplotlib, Agg)
- :mod:`.overlay_document`: runs of several stations aligned by key, a part's runs as data
  for the line's page
- :mod:`.program_band`: a program's recent runs as a band (lowest, highest, median) to draw
  one run against
"""

from shared.offline.overlay.overlay_alignment import Alignment, align_index, parse_alignment
from shared.offline.overlay.overlay_document import aligned, part_overlay_document
from shared.offline.overlay.overlay_plot import build_figure, run_colours, save_figure
from shared.offline.overlay.overlay_run import (
    OverlayRun,
    find_run_files,
    overlay_run_of,
    read_overlay_cycle,
    read_overlay_run,
)
from shared.offline.overlay.overlay_series import Overlay, build_overlay
from shared.offline.overlay.program_band import program_band_document

__all__ = [
    "Alignment",
    "Overlay",
    "OverlayRun",
    "align_index",
    "aligned",
    "build_figure",
    "build_overlay",
    "find_run_files",
    "overlay_run_of",
    "parse_alignment",
    "part_overlay_document",
    "program_band_document",
    "read_overlay_cycle",
    "read_overlay_run",
    "run_colours",
    "save_figure",
]
