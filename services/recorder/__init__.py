"""Recorder: MCAP files per run, Rerun, and the machine-wear ledger.

- :mod:`.service`: the service (zenoh wiring: subscriptions per station, the wear
  queryable, RecorderStats, the flush ticks), :mod:`.arguments` its options
- :mod:`.live`: what a line sends, filed per station and run (inbox, classify,
  batches, files, health)
- :mod:`.mcap_files`: MCAP written, read back, recovered, exported
- :mod:`.rerun_files`: Rerun ``.rrd`` files and the live view
- :mod:`.foxglove_live`: the live Foxglove WebSocket (``--foxglove-port``) and its layout
- :mod:`.wear`: the wear ledger (per tool), its bound, alerts, reset, the plant view
- :mod:`.post_mortem`: the paper's figures of a recorded run (``boltwatch inspect``)
- :mod:`.overlay`: several recorded runs on one figure (``boltwatch inspect --overlay``)
- :mod:`.quality`: statistics per program (``boltwatch report``)
- :mod:`.controller_import`: controller runs into recordings (``boltwatch import``)

Each room's ``__init__`` says what each of its files is. Test helpers (a
recorder in a thread, station files on loopback) are in ``tests/live_recorder.py``.
"""
