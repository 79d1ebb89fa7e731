"""Rerun: an ``.rrd`` beside each run's MCAP, and the live view.

- :mod:`.rerun_sink`: one run's Rerun recording, written in column batches
- :mod:`.rerun_streams`: recording streams pooled per station (and why)
- :mod:`.rerun_blueprint`: entity paths and the layout (``boltwatch.rbl``)
- :mod:`.rrd_recovery`: a truncated ``.rrd`` made readable
- :mod:`.rrd_from_mcap`: a run's ``.rrd`` made from its MCAP (``inspect --rerun``), for
  recorders that write MCAP only
"""
