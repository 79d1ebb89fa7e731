"""Recordings, without zenoh: where a run's files go, what is recorded, and the file formats.

- :mod:`.layout` (where a run's files go and how to find them: the one rule; the name a
  file has while it is written)
- :mod:`.received` (one received payload, classified, checked and decoded: what
  every sink writes), :mod:`.sink` (the shape every writer of a run shares)
- :mod:`.file_metadata` (the metadata records of a recording)
- :mod:`.mcap` (MCAP: written, read back, recovered, exported), :mod:`.rerun`
  (Rerun ``.rrd``: written, recovered, made from MCAP)
"""

from shared.recordings.file_metadata import FileMetadata, flatten, software_version
from shared.recordings.layout import (
    FileName,
    check_walkable,
    file_name_of,
    file_path,
    final_path_of,
    loop_lines,
    recording_files,
    rerun_path,
    run_file_prefix,
    run_files,
    station_days,
    station_folder_name,
    unfinished_files,
    writing_path,
)
from shared.recordings.received import MAX_AHEAD_S, OTHER_STATION, Received, classify
from shared.recordings.sink import Sink

__all__ = [
    "FileMetadata",
    "FileName",
    "MAX_AHEAD_S",
    "OTHER_STATION",
    "Received",
    "Sink",
    "check_walkable",
    "classify",
    "file_name_of",
    "file_path",
    "final_path_of",
    "flatten",
    "loop_lines",
    "software_version",
    "recording_files",
    "rerun_path",
    "run_file_prefix",
    "run_files",
    "station_days",
    "station_folder_name",
    "unfinished_files",
    "writing_path",
]
