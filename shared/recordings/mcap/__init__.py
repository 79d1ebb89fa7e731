"""MCAP files: written, read back, made valid after a crash, exported.

- :mod:`.mcap_sink`: one MCAP file being written (schema'd JSON channels, zstd, flush)
- :mod:`.mcap_messages`: a batch of messages packed into the writer's open chunk at once
- :mod:`.recording_reader`: a recording read back, message by message
- :mod:`.recovery`: a truncated MCAP made valid (``boltwatch recover``)
- :mod:`.trace_export`: a recording as a CSV trace (``boltwatch export``)
"""
