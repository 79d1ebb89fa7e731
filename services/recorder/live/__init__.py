"""Live recording: what a line sends, filed into one MCAP file (and Rerun) per run.

- :mod:`.line_inbox`: zenoh's receive thread keeps each message, the worker takes batches
- :mod:`.sample_batches`: a station's batch filed as the samples it holds
- :mod:`.recorder`: payloads into each station's files, disk faults
- :mod:`.run_files`: one file (and its parts) per run, rotation, the late grace
- :mod:`.free_space`: no new file below a reserve of free space
- :mod:`.recorder_health`: lag, counts and errors per station (``RecorderStats``)
- :mod:`.spool_order`: where each numbered message of a station's spool goes (live,
  into a hole being filled again, skipped, deferred); pure
- :mod:`.spool_keeper`: the orders of every spool, what is filed saved and acknowledged

A payload is classified and checked by :mod:`shared.recordings.received`; files
are named by :mod:`shared.recordings.layout` and written by the sinks of
:mod:`shared.recordings`.
"""
