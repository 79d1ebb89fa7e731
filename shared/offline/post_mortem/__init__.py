"""Post-mortem: the paper's figures of one recorded run (``boltwatch inspect``).

- :mod:`.post_mortem_run`: a run read back from its recording
- :mod:`.post_mortem_errors`: prediction errors (eqs. 61-63)
- :mod:`.post_mortem_panels`: the panels of Figures 10, 13-15, 22, 23
- :mod:`.run_plot`: the figure drawn and saved
"""
