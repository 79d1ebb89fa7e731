"""The last part scanned at each station the recorder serves: kept, saved, and answered.

The line's PLC puts each part on ``boltwatch/<st>/part``; the recorder files
it like any message, and keeps the last scan of each station it serves (by
arrival, as a predictor does). A station's predictor that starts (again) asks
the line for it (``services/predictor/part_at_start.py``): a queryable on
``boltwatch/<st>/part`` answers with the scan, its JSON as the PLC put it, on
the station's own key; with an error reply saying so when none is known.

What it keeps is saved in ``<recordings>/.parts/<station>.json`` (replaced
atomically, at the recorder's tick when it changed) and read at start, so a
restarted recorder still knows each station's part. A recorder killed loses
at most the scans of its last tick from the file; a save that fails is
logged and tried again at the next tick (the part stays known meanwhile). A
file that does not read is logged once, and the station's part is unknown
until its next scan.
"""

from __future__ import annotations

import json
import logging
import threading
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import Final

import zenoh

from shared.contract import PartScan, channels, decode, encode, to_dict
from shared.errors import InputError
from shared.files import describe_os_error, write_json_atomically

LOG = logging.getLogger(__name__)

#: where the last parts are saved, in the recordings folder
PARTS_FOLDER: Final = ".parts"


class LastParts:
    """The last part scan of each served station (the worker keeps, zenoh's threads read)."""

    def __init__(self, recordings_folder: Path, station_ids: Iterable[str]) -> None:
        self._folder = recordings_folder / PARTS_FOLDER
        self._stations = frozenset(station_ids)
        self._lock = threading.Lock()
        self._scans: dict[str, PartScan] = {}
        self._unsaved: set[str] = set()
        self.save_errors = 0
        self.last_error: str | None = None
        for station in self._stations:
            scan = self._load(station)
            if scan is not None:
                self._scans[station] = scan

    def of(self, station: str) -> PartScan | None:
        """The last part scanned at ``station`` (None: none known)."""
        with self._lock:
            return self._scans.get(station)

    def on_scan(self, scan: PartScan, station: str) -> None:
        """A part scan filed (the worker) from ``station``'s key: that station's part from now
        on (one naming another station, or of a station it does not serve: not kept)."""
        if scan.station != station or station not in self._stations:
            return
        with self._lock:
            self._scans[scan.station] = scan
            self._unsaved.add(scan.station)

    def save(self) -> None:
        """Save what changed since the last save (the worker, at its tick and at the end)."""
        with self._lock:
            unsaved = {station: self._scans[station] for station in self._unsaved}
            self._unsaved.clear()
        for station, scan in unsaved.items():
            path = self._path(station)
            try:
                write_json_atomically(path, to_dict(scan))
            except OSError as err:
                self.save_errors += 1
                self.last_error = describe_os_error(err, path)
                LOG.error("last part of %s not saved (tried again): %s", station, self.last_error)
                with self._lock:
                    self._unsaved.add(station)

    def replier(self, station: str) -> Callable[[zenoh.Query], None]:
        """The callback of the queryable ``boltwatch/<station>/part``."""
        key = channels.PART.key(station)

        def reply(query: zenoh.Query) -> None:
            with query:  # finalized on leaving: the querier's get ends now
                scan = self.of(station)
                if scan is None:
                    query.reply_err(f"no part scanned at {station} known to the line".encode())
                else:
                    query.reply(key, encode(scan))

        return reply

    def _path(self, station: str) -> Path:
        return self._folder / f"{station}.json"

    def _load(self, station: str) -> PartScan | None:
        path = self._path(station)
        try:
            scan = decode(PartScan, path.read_bytes())
        except FileNotFoundError:
            return None
        except (OSError, InputError, json.JSONDecodeError) as err:
            LOG.error("%s: unreadable, the part at %s is unknown until its next scan: %s",
                      path, station, err)  # fmt: skip
            return None
        if scan.station != station:
            LOG.error("%s names station %s: the part at %s is unknown", path, scan.station, station)
            return None
        return scan
