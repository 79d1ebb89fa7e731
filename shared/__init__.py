"""Code every boltwatch service uses: configuration, message contracts and
codecs, zenoh and CAN helpers, and the paper's analytical model.

``shared`` never imports ``services`` (an import-linter contract checks it).

- :mod:`.config` (station, joint and line files), :mod:`.model` (the paper's
  analytical model), :mod:`.errors` (the exception tree)
- contracts: :mod:`.messages` (payloads), :mod:`.keys` (zenoh key expressions),
  :mod:`.message_fields` (every field's bounds), :mod:`.message_shape` (what a
  decoder derives from a type), :mod:`.codec` (JSON and schemas), :mod:`.trace`
  (the offline CSV), :mod:`.channels` (every channel: topic, message, publisher),
  :mod:`.tightening_judgement` (a run's figures against its windows: OK/NOK)
- CAN: :mod:`.can_bus` (open the bus), :mod:`.can_database` (the DBC, checked),
  :mod:`.sensor_range` (what the sensors can measure)
- zenoh: :mod:`.zenoh_session` (sessions, the router link), :mod:`.queued_publisher`
  (publish without waiting), :mod:`.sample_batching` (an edge station's samples in
  batches toward the line), :mod:`.receive_threads` (cheap callbacks)
- a service's life: :mod:`.service_runtime` (start, signals, stop),
  :mod:`.supervisor_link` (stop when ``boltwatch up`` dies), :mod:`.realtime`
  (SCHED_FIFO for the stop path), :mod:`.logging_setup`, :mod:`.log_limit` (one
  line for a flood), :mod:`.folders` (make a folder or say why not)
- :mod:`.option_types` (argparse types that refuse impossible numbers)
- :mod:`.run_clock` (a run's clock: epoch ns <-> seconds since the run started)
"""
