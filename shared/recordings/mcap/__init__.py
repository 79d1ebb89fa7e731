"""MCAP files: written, read back, made valid after a crash, exported.

- :mod:`.mcap_sink`: one MCAP file being written (schema'd JSON channels, zstd, flush)
- :mod:`.mcap_messages`: a batch of messages packed into the writer's open chunk at once
- :mod:`.recording_reader`: a recording read back, message by message
- :mod:`.recovery`: a truncated MCAP made valid (``boltwatch recover``)
- :mod:`.unfinished_files`: files a crash left under their writing name, made run files
- :mod:`.spool_marks`: the spool numbers a file holds, last in each chunk, and read back
- :mod:`.trace_export`: a recording's samples of a run (its trace), and as a CSV trace
  (``boltwatch export``)
"""


from shared.recordings.mcap.mcap_messages import MessageAppender, MessageRow
from shared.recordings.mcap.mcap_sink import McapSink, RAW_ENCODING, RAW_REASON
from shared.recordings.mcap.recording_reader import RecordingScan
from shared.recordings.mcap.recovery import default_target, recover, remove_unfinished
from shared.recordings.mcap.spool_marks import FileMarks, SpoolKey, filed_in
from shared.recordings.mcap.trace_export import (
    SAMPLE_SCHEMA,
    export_trace,
    read_samples,
    run_times_s,
)
from shared.recordings.mcap.unfinished_files import (
    FinishedCount,
    Unfinished,
    finish_one,
    finish_unfinished,
)

__all__ = ["default_target", "export_trace", "FileMarks", "filed_in", "finish_one", "finish_unfinished", "FinishedCount", "McapSink", "MessageAppender", "MessageRow", "RAW_ENCODING", "RAW_REASON", "read_samples", "RecordingScan", "recover", "remove_unfinished", "run_times_s", "SAMPLE_SCHEMA", "SpoolKey", "Unfinished"]
