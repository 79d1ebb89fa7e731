"""Predictor: the paper's real-time stick-slip algorithm (Section 6) on live samples.

- :mod:`.core`: the pure algorithm (samples in, events and decisions out)
- :mod:`.service` (zenoh wiring), :mod:`.arguments`, :mod:`.station_inbox`,
  :mod:`.served_station` (one station's configuration), :mod:`.active_run`
  (one run's core and summary), :mod:`.run_result` (a run's summary judged against its
  program's windows: its TighteningResult), :mod:`.run_messages` (core outputs as messages,
  live and replayed alike), :mod:`.station_counts` (what it could not use, per
  station: PredictorStats), :mod:`.station_runs` (one station's runs: states and
  samples in, messages out, for both placements), :mod:`.station_refusal` (one
  predictor per station)
- :mod:`.edge_predictor`: the station's predictor on its acquisition's CAN thread
  (``[predictor] placement = "edge"``, the default)
- :mod:`.trace_replay`: the core over an offline trace (``boltwatch predict``)
- :mod:`.advisory_replay`: the core over a run a controller stopped, after the fact
  (``boltwatch import`` and the Open Protocol bridge)
"""
