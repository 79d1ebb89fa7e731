"""Live recording: what a line sends, filed into one MCAP file (and Rerun) per run.

- :mod:`.line_inbox`: zenoh's receive thread keeps each message, the worker takes batches
- :mod:`.incoming`: classify and decode one payload (refused ones kept raw)
- :mod:`.sample_batches`: a station's batch filed as the samples it holds
- :mod:`.recorder`: payloads into each station's files, disk faults
- :mod:`.run_files`: one file (and its parts) per run, rotation, the late grace
- :mod:`.file_metadata`: what each file says of its station and program
- :mod:`.recorder_health`: lag, counts and errors per station (``RecorderStats``)
"""
