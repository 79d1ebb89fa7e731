"""Where the bridge was: the newest tightening it has published, kept across restarts.

A bridge killed (SIGKILL, power) and started again must neither lose a
tightening nor publish one twice. The controller keeps its results and serves
them by id (MID 0064 -> 0065), so the bridge only has to know the id up to
which it has published every tightening: the **watermark**. It is kept in a
small JSON file in the station's recordings folder
(``openprotocol_<station>.json``), written atomically (a temporary file in the
same folder, fsync, rename, fsync of the folder): after a crash the file holds
the old watermark or the new one, never half of either.

The bridge writes it after the tightening's messages were put on zenoh (on
the publisher's thread, :meth:`QueuedPublisher.call`): a bridge killed between
the put and the write publishes that one tightening again when it comes back
(its run id is the same, so the wear ledger and ``up`` count it once); killed
before the put, it fetches it again. Nothing is lost either way.

The file also keeps the **keys** of the ids published last (time stamp,
pset, torque, angle, verdict, part as the controller wrote them), so that a
result sent again is told from another result under the same id, and the
reading of the controller's 0900 samples that agreed with its results
(:mod:`.curve_check`).

A controller whose ids started again is a new **epoch** of the station's
controller (:mod:`.bridge` tells when: it has no result though some were
published, its newest id is below the watermark, its result at the watermark
is another one, an id at or below the watermark comes with another key: reset,
replaced, or wrapped after 9999999999; it names itself differently in MID
0002; or, within a session, a live id jumps more than a gap can hold past the
newest one): its runs get run ids past every run id published before
(``run_id = run_id_offset + tightening_id``; the offset is the last run id
published less the id after which the epoch starts, so the run ids go on one
by one: an epoch that starts after id 3117 gives id 3118 the run id after the
last one; the offset may be negative), and none of them is taken for one
published already. The tightening id of each result stays the controller's
own. The keys of the epochs before (``previous_keys``, the newest
:data:`PREVIOUS_KEYS_KEPT`) are kept too: a result of an epoch before is
never published again, and where the controller's ids went back to ones it
still keeps, the new epoch starts after the last of them.
"""

from __future__ import annotations

import json
import logging
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path

from shared.files import write_json_atomically

LOG = logging.getLogger(__name__)

#: how many keys of the epochs before are kept
PREVIOUS_KEYS_KEPT = 200


@dataclass(frozen=True, slots=True)
class BridgePosition:
    """What a bridge has published of its controller's tightenings."""

    #: every tightening id up to this one is published (or given up: refused); 0: none yet
    watermark: int = 0
    #: added to a tightening id to make its run id (0 until the controller's ids restart)
    run_id_offset: int = 0
    #: the controller's name from MID 0002 when the watermark was written ("" unknown)
    controller_name: str = ""
    #: the keys of the ids published last, by id (:attr:`ResultFigures.key`)
    keys: Mapping[int, str] = field(default_factory=dict)
    #: how the controller's 0900 samples read right (``Reading.text``); "" not known yet
    trace_reading: str = ""
    #: the keys of the ids published last in the epochs before, by id (newest last)
    previous_keys: Mapping[int, str] = field(default_factory=dict)

    def run_id(self, tightening_id: int) -> int:
        return self.run_id_offset + tightening_id

    def new_epoch(self, controller_name: str, start_after: int = 0) -> BridgePosition:
        """The controller's ids start again after ``start_after``: the run ids go on after
        the last one published; this epoch's keys join those of the epochs before."""
        merged = {i: k for i, k in self.previous_keys.items() if i not in self.keys}
        merged.update(sorted(self.keys.items()))
        kept = dict(list(merged.items())[-PREVIOUS_KEYS_KEPT:])
        offset = self.run_id(self.watermark) - start_after
        return BridgePosition(start_after, offset, controller_name, previous_keys=kept)


def position_path(recordings: Path, station: str) -> Path:
    """``<recordings>/openprotocol_<station>.json``."""
    return recordings / f"openprotocol_{station}.json"


def read_position(path: Path) -> BridgePosition:
    """The position written last; a missing file is the start (nothing published).

    A file that cannot be read as one (a disk fault, edited by hand) is logged
    and taken as the start: the controller's newest result then decides where
    to go on (never lost, maybe published again under the same run id)."""
    try:
        document = json.loads(path.read_text(encoding="utf-8"))
        position = BridgePosition(
            watermark=_count(document, "watermark"),
            run_id_offset=_whole(document, "run_id_offset"),
            controller_name=str(document.get("controller_name", "")),
            keys=_keys(document, "keys"),
            trace_reading=str(document.get("trace_reading", "")),
            previous_keys=_keys(document, "previous_keys"),
        )
    except FileNotFoundError:
        return BridgePosition()
    except (OSError, ValueError, TypeError, AttributeError) as err:
        LOG.error("%s: unreadable (%s): starting from the controller's newest result", path, err)
        return BridgePosition()
    return position


def write_position(path: Path, position: BridgePosition) -> None:
    """Replace the file by ``position`` atomically (temporary + fsync + rename + fsync)."""
    write_json_atomically(path, _document(position))


def _document(position: BridgePosition) -> dict[str, object]:
    return {
        "watermark": position.watermark,
        "run_id_offset": position.run_id_offset,
        "controller_name": position.controller_name,
        "keys": {str(tightening_id): key for tightening_id, key in position.keys.items()},
        "trace_reading": position.trace_reading,
        "previous_keys": {str(i): key for i, key in position.previous_keys.items()},
    }


def _keys(document: dict[str, object], name: str) -> dict[int, str]:
    keys = document.get(name, {})
    if not isinstance(keys, dict):
        raise ValueError(f"{name}: expected an object, got {keys!r}")
    return {int(tightening_id): str(key) for tightening_id, key in keys.items()}


def _whole(document: dict[str, object], key: str) -> int:
    value = document.get(key, 0)
    if isinstance(value, bool) or not isinstance(value, int):
        raise ValueError(f"{key}: expected a whole number, got {value!r}")
    return value


def _count(document: dict[str, object], key: str) -> int:
    value = document.get(key, 0)
    if isinstance(value, bool) or not isinstance(value, int) or value < 0:
        raise ValueError(f"{key}: expected a count, got {value!r}")
    return value
