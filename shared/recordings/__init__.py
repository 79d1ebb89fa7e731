"""(to be written)"""

from shared.recordings.file_metadata import FileMetadata, flatten
from shared.recordings.layout import (
    file_path,
    recording_files,
    rerun_path,
    run_file_prefix,
    run_files,
    station_days,
    station_folder_name,
)
from shared.recordings.received import MAX_AHEAD_S, OTHER_STATION, Received, classify
from shared.recordings.sink import Sink

__all__ = [
    "FileMetadata",
    "MAX_AHEAD_S",
    "OTHER_STATION",
    "Received",
    "Sink",
    "classify",
    "file_path",
    "flatten",
    "recording_files",
    "rerun_path",
    "run_file_prefix",
    "run_files",
    "station_days",
    "station_folder_name",
]
