"""Controller runs into recordings (``boltwatch import``).

- :mod:`.controller_run`: a controller's JSON run read and checked
- :mod:`.controller_steps`: the controller's own result (steps, functions, verdict)
- :mod:`.controller_timing`: its clock
- :mod:`.controller_import`: a run replayed through the predictor core into recordings
  (its TighteningResult: :mod:`shared.quality.controller_result`)
- :mod:`.import_files`: a run's files written whole or not at all
"""

from shared.offline.controller_import.controller_import import (
    DEFAULT_STATION,
    RunNotWrittenError,
    check_station_id,
    import_run,
)
from shared.offline.controller_import.controller_run import ControllerRun, read_controller_run
from shared.offline.controller_import.import_files import (
    read_copy,
    remove_temporary,
    temporary_path,
)

__all__ = [
    "DEFAULT_STATION",
    "ControllerRun",
    "RunNotWrittenError",
    "check_station_id",
    "import_run",
    "read_controller_run",
    "read_copy",
    "remove_temporary",
    "temporary_path",
]
