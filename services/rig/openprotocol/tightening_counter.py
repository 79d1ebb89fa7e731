"""The simulated controller's tightening counter, kept across restarts as a controller keeps it.

A real controller numbers its tightenings on and on, power cycles included;
an integrator relies on it (a new result's id is past every id it has seen,
a gap in the ids is results it missed). The simulated controller keeps its
last tightening id in ``<recordings>/simulated_controller_<station>.json``,
written after each tightening (temporary file, fsync, rename), and numbers
the next process's first tightening one past it (1 on a fresh machine).
``--first-run-id`` overrides it.
"""

from __future__ import annotations

import json
import logging
import os
import tempfile
from pathlib import Path

LOG = logging.getLogger(__name__)


class TighteningCounter:
    """The last tightening id, in a small JSON file."""

    def __init__(self, path: Path) -> None:
        self.path = path

    @classmethod
    def of_station(cls, recordings: Path, station_id: str) -> TighteningCounter:
        return cls(recordings / f"simulated_controller_{station_id}.json")

    def last(self) -> int:
        """The last tightening id kept (0: none, or a file that cannot be read: logged)."""
        try:
            value = json.loads(self.path.read_text())["last_tightening_id"]
        except FileNotFoundError:
            return 0
        except (OSError, ValueError, KeyError, TypeError) as err:
            LOG.warning("%s: unreadable (%s): tightening ids start again at 1", self.path, err)
            return 0
        return value if isinstance(value, int) and value >= 0 else 0

    def keep(self, tightening_id: int) -> None:
        """Write ``tightening_id`` atomically; a failure is logged, the tool goes on."""
        try:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            handle, temporary = tempfile.mkstemp(dir=self.path.parent, suffix=".tmp")
            with os.fdopen(handle, "w") as out:
                json.dump({"last_tightening_id": tightening_id}, out)
                out.flush()
                os.fsync(out.fileno())
            os.replace(temporary, self.path)
        except OSError as err:
            LOG.warning("%s: cannot keep the tightening counter: %s", self.path, err)
