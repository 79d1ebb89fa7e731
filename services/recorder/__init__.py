"""Recorder: MCAP files per run, Rerun, and the machine-wear ledger.

Files, one concept each:

- live recording: :mod:`.service` (zenoh wiring), :mod:`.arguments`,
  :mod:`.line_inbox`, :mod:`.incoming` (classify and decode), :mod:`.sample_batches`
  (a batch filed as its samples), :mod:`.recorder`
  (payloads into files, disk faults), :mod:`.run_files` (one file per run),
  :mod:`.mcap_sink`, :mod:`.file_metadata`, :mod:`.recorder_health`
- Rerun: :mod:`.rerun_sink`, :mod:`.rerun_streams`, :mod:`.rerun_blueprint`
- wear: :mod:`.wear_ledger` (SQLite), :mod:`.wear_bound` (what a run can have
  taken: the bound a summary must keep), :mod:`.wear_ledger_file` (a ledger made
  whole, a broken one recognised and moved aside), :mod:`.wear_watch`
  (summaries in, alerts out, a failing or broken ledger waited out),
  :mod:`.wear_waiting` (runs still waiting when the recorder stops),
  :mod:`.wear_reset` (``boltwatch wear reset``), :mod:`.wear_table`,
  :mod:`.wear_plant` (every line's ledger merged: ``boltwatch wear --plant``)
- reading back: :mod:`.recording_reader`, :mod:`.trace_export`,
  :mod:`.recovery`, :mod:`.rrd_recovery`, and the post-mortem
  :mod:`.run_plot`, :mod:`.post_mortem_run`, :mod:`.post_mortem_panels`,
  :mod:`.post_mortem_errors`
- controller runs (``boltwatch import``): :mod:`.controller_run` (the JSON),
  :mod:`.controller_steps` (the controller's result), :mod:`.controller_timing`
  (its clock), :mod:`.controller_import` (into recordings),
  :mod:`.import_files` (whole or not at all)
- :mod:`.testing`: helpers for tests (station files on loopback, free ports)
"""
