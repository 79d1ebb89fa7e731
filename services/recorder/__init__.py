"""``boltwatch serve recorder``: everything a line's stations say, into recordings and the ledger.

- :mod:`.service` (the zenoh wiring: subscriptions per station, the wear
  queryable, RecorderStats, the flush ticks), :mod:`.arguments` (its options),
  :mod:`.served_stations` (the station files it serves, which must agree),
  :mod:`.live_views` (Rerun's viewer and the Foxglove WebSocket, started when asked for)
- :mod:`.live` (what a line sends, filed per station and run: inbox, batches,
  run files, health, the order of stations' spooled messages and their
  acknowledgements)
- :mod:`.wear_watch` (summaries into the wear ledger, alerts when a tool is
  due, a failing ledger waited out), :mod:`.quality_watch` (the quality alert)
- :mod:`.foxglove_live` (the live Foxglove WebSocket and its layout)

What it writes, and how, is the library's: :mod:`shared.recordings`,
:mod:`shared.wear`, :mod:`shared.quality`.
"""
