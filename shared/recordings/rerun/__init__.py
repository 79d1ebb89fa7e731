"""Rerun: an ``.rrd`` beside each run's MCAP, and the live view.

- :mod:`.rerun_sink`: one run's Rerun recording, written in column batches
- :mod:`.rerun_streams`: recording streams pooled per station (and why)
- :mod:`.rerun_blueprint`: entity paths and the layout (``boltwatch.rbl``)
- :mod:`.rrd_recovery`: a truncated ``.rrd`` made readable
- :mod:`.rrd_from_mcap`: a run's ``.rrd`` made from its MCAP (``inspect --rerun``), for
  recorders that write MCAP only
"""


from shared.recordings.rerun.rerun_sink import LIVE_BATCH_SAMPLES, RerunLive, RerunOptions, RerunSink, open_rerun_sink
from shared.recordings.rerun.rerun_streams import BLUEPRINT_FILE
from shared.recordings.rerun.rrd_from_mcap import rrd_from_mcap
from shared.recordings.rerun.rrd_recovery import check_rrd, recover_rrd, rows_by_entity

__all__ = ["BLUEPRINT_FILE", "LIVE_BATCH_SAMPLES", "RerunLive", "RerunOptions", "RerunSink", "check_rrd", "open_rerun_sink", "recover_rrd", "rows_by_entity", "rrd_from_mcap"]
