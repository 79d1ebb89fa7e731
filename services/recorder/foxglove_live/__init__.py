"""The live Foxglove view of what the recorder files (``serve recorder --foxglove-port``).

- :mod:`.foxglove_server`: the Foxglove WebSocket server, one channel per station and
  channel with the MCAP files' JSON schemas, fed by the recorder's worker, never waited on
- :mod:`.foxglove_layout`: the Foxglove layout of a station (torque and preload over time,
  torque over angle, OK/NOK, the decisions), written to ``config/foxglove/``
"""
