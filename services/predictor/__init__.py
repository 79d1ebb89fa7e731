"""``boltwatch serve predictor``: the stick-slip library (:mod:`shared.stickslip`) on live samples.

- :mod:`.service` (the zenoh wiring), :mod:`.arguments` (its options),
  :mod:`.station_inbox` (every served station's samples and tool states, one at a time)
- :mod:`.served_station` (one station's configuration), :mod:`.station_runs` (one
  station's runs: states and samples in, messages out, for both placements),
  :mod:`.active_run` (one run's core and summary)
- :mod:`.station_counts` (what it could not use, per station: PredictorStats),
  :mod:`.station_refusal` (one predictor per station)
- :mod:`.part_at_start` (the part at each station when the predictor starts: asked of
  the line in the background)
- :mod:`.edge_predictor` (the station's predictor on its acquisition's CAN thread,
  ``[predictor] placement = "edge"``, the default; the command line hands it to the
  acquisition through the acquisition's ``Decider`` seam)
"""
