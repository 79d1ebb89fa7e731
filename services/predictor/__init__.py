"""Predictor: the paper's real-time stick-slip algorithm (Section 6) on live samples.

- :mod:`.core`: the pure algorithm (samples in, events and decisions out)
- :mod:`.service` (zenoh wiring), :mod:`.arguments`, :mod:`.station_inbox`,
  :mod:`.served_station` (one station's configuration), :mod:`.active_run`
  (one run's core and summary), :mod:`.run_messages` (core outputs as messages,
  live and replayed alike), :mod:`.station_counts` (what it could not use, per
  station: PredictorStats)
- :mod:`.trace_replay`: the core over an offline trace (``boltwatch predict``)
"""
