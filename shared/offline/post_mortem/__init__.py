"""Post-mortem: the paper's figures of one recorded run (``boltwatch inspect``).

- :mod:`.post_mortem_run`: a run read back from its recording
- :mod:`.post_mortem_errors`: prediction errors (eqs. 61-63)
- :mod:`.post_mortem_panels`: the panels of Figures 10, 13-15, 22, 23
- :mod:`.run_plot`: the figure drawn and saved
"""

from shared.offline.post_mortem.post_mortem_errors import prediction_errors
from shared.offline.post_mortem.post_mortem_panels import plateau_bars
from shared.offline.post_mortem.post_mortem_run import read_run
from shared.offline.post_mortem.run_plot import build_figure, draw_run

__all__ = ["build_figure", "draw_run", "plateau_bars", "prediction_errors", "read_run"]
