"""``boltwatch serve recorder``: everything a line's stations say, into recordings, the results
store and the wear ledger.

- :mod:`.service` (the zenoh wiring: subscriptions per station, RecorderStats,
  the flush ticks), :mod:`.wear_queryable` (``boltwatch/<st>/wear`` answered),
  :mod:`.last_parts` (each station's last part scan, kept, saved and answered on
  ``boltwatch/<st>/part``),
  :mod:`.arguments` (its options),
  :mod:`.served_stations` (the station files it serves, which must agree),
  :mod:`.station_holder` (one recorder per station: the folder's lock, the station's token),
  :mod:`.live_views` (Rerun's viewer and the Foxglove WebSocket, started when asked for)
- :mod:`.live` (what a line sends, filed per station and run: inbox, batches,
  run files, health, the order of stations' spooled messages and their
  acknowledgements)
- :mod:`.wear_watch` (summaries into the wear ledger, alerts when a tool is
  due, a failing ledger waited out), :mod:`.wear_forecasts` (each tool's service
  forecast after its runs: a WearForecast within a horizon), :mod:`.quality_watch`
  (the quality alert),
  :mod:`.results_watch` (results into the results store, from a thread of its
  own; a failing store waited out, the recordings read at start for what it lacks)
- :mod:`.foxglove_live` (the live Foxglove WebSocket and its layout)

What it writes, and how, is the library's: :mod:`shared.recordings`,
:mod:`shared.wear`, :mod:`shared.quality`, :mod:`shared.results`.
"""
