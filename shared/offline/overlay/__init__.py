"""Overlay: several recorded runs on one figure (``boltwatch inspect --overlay``).

- :mod:`.overlay_run`: one run read back (samples, events, result), found by id or path
- :mod:`.overlay_alignment`: where runs are aligned (start, a torque, the first slip)
- :mod:`.overlay_series`: the plotted series, aligned, and the programs' windows (data only)
- :mod:`.overlay_plot`: the figure drawn and saved (matplotlib, Agg)
"""
