"""Overlay: several recorded runs on one figure (``boltwatch inspect --overlay``).

- :mod:`.overlay_run`: one run read back (samples, events, result), found by id or path;
  a multi-spindle cycle's runs
- :mod:`.overlay_alignment`: where runs are aligned (start, a torque, the first slip)
- :mod:`.overlay_series`: the plotted series, aligned, and the programs' windows (data only)
- :mod:`.overlay_plot`: the figure drawn and saved (matplotlib, Agg)
"""

from shared.offline.overlay.overlay_alignment import align_index, parse_alignment
from shared.offline.overlay.overlay_plot import build_figure, run_colours, save_figure
from shared.offline.overlay.overlay_run import (
    OverlayRun,
    find_run_files,
    read_overlay_cycle,
    read_overlay_run,
)
from shared.offline.overlay.overlay_series import Overlay, build_overlay

__all__ = [
    "Overlay",
    "OverlayRun",
    "align_index",
    "build_figure",
    "build_overlay",
    "find_run_files",
    "parse_alignment",
    "read_overlay_cycle",
    "read_overlay_run",
    "run_colours",
    "save_figure",
]
