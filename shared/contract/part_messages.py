"""What the line says of the part at a station: which work piece the next runs tighten.

Re-exported by :mod:`shared.contract.messages`. Same rules as every message
there. A tool on CAN knows nothing of the part it tightens; the line does:
its PLC, or a scanner at the station, reads the part's id (a serial number,
a VIN, the text of a data matrix code) when the part arrives, and puts a
:class:`PartScan` on ``boltwatch/<st>/part`` before the part's first run (as
an Open Protocol VIN download, MID 0050, tells a tool controller). The
station's predictor keeps the last one and names it in the result of every
run that starts after it (``TighteningResult.part_id``), until the next, and
says where that part came from (``TighteningResult.part_source``,
:data:`PartSource`). The line's recorder keeps each station's last scan and
answers a query of ``boltwatch/<st>/part`` with it: a predictor that starts
(again) asks it for the part at its station.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

from shared.contract.message_fields import WIRE_CONFIG, PartId, StationId, TimeNs


@dataclass(frozen=True, slots=True)
class PartScan:
    """A part arrived at the station: the runs that start from now on tighten it.

    Its id holds until the next scan: a part with four bolts is scanned once,
    before its first run. A scan that arrives while a run is in progress
    belongs to the next run (the one in progress started on the part before).
    No scan since the predictor started: the results name the part the line's
    recorder last heard of, as its answer when the predictor started (``restored``),
    else none (None).
    """

    __pydantic_config__ = WIRE_CONFIG

    station: StationId
    part_id: PartId  # as scanned: a serial number, a VIN, the text of a data matrix code
    time_ns: TimeNs  # when it was scanned


#: where the part a live run's result names came from, as far as its predictor knows:
#: ``scanned``: a scan the predictor heard before the run started (the part as the line
#: said it); ``restored``: the last part the line's recorder had heard when the predictor
#: started (asked of the line; a scan came later to none): stale if another part arrived
#: while the station was down and its scan never reached the line; ``unknown``: no part
#: (none scanned since the predictor started, and the line knew none or did not answer)
PartSource = Literal["scanned", "restored", "unknown"]
