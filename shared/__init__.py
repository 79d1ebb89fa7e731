"""Code every boltwatch service uses: configuration, message contracts and
codecs, zenoh and CAN helpers, and the paper's analytical model.

``shared`` never imports ``services`` (an import-linter contract checks it).

- :mod:`.config` (station, joint and line files), :mod:`.model` (the paper's
  analytical model), :mod:`.errors` (the exception tree)
- contracts: :mod:`.channels` (every channel of a line: topic, message type,
  schema name, QoS, publisher), :mod:`.messages` (payloads), :mod:`.keys` (zenoh
  key expressions), :mod:`.message_fields` (every field's bounds),
  :mod:`.codec` (JSON and schemas, pydantic), :mod:`.message_shape` (a refused
  payload looked at field by field), :mod:`.trace` (the offline CSV),
  :mod:`.tightening_judgement` (a run's figures against its windows: OK/NOK),
  :mod:`.controller_judgement` (a controller's own result as a TighteningResult),
  :mod:`.stopped_run` (a run a controller stopped, and the predictor's replay of it)
- CAN: :mod:`.can_bus` (open the bus), :mod:`.can_database` (the DBC, checked),
  :mod:`.sensor_range` (what the sensors can measure)
- zenoh: :mod:`.zenoh_session` (sessions, the router link), :mod:`.queued_publisher`
  (publish without waiting), :mod:`.sample_batching` (an edge station's samples in
  batches toward the line), :mod:`.receive_threads` (cheap callbacks)
- a service's life: :mod:`.service_skeleton` (its session, health tokens,
  declarations and stop order in one ExitStack), :mod:`.service_runtime` (the
  work thread, signals, exit status),
  :mod:`.supervisor_link` (stop when ``boltwatch up`` dies), :mod:`.realtime`
  (SCHED_FIFO for the stop path), :mod:`.logging_setup`, :mod:`.log_limit` (one
  line for a flood), :mod:`.folders` (make a folder or say why not)
- :mod:`.openprotocol` (Atlas Copco Open Protocol: framing and messages, no sockets)
- :mod:`.line_status` (what a line's stations say: ``boltwatch status`` and the line's page)
- :mod:`.option_types` (argparse types that refuse impossible numbers)
- :mod:`.run_clock` (a run's clock: epoch ns <-> seconds since the run started)
"""
