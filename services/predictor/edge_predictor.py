"""The predictor of one station on its acquisition's CAN thread: the stop path of one sample.

Where the decision runs (``docs/explanation/decisions/0001-edge-stop-decision.md``): a station whose
``[predictor] placement`` is ``"edge"`` (the default) decides in its
acquisition process, on the thread that reads the CAN bus. Each complete
sample goes from the frame decoder through :class:`StationRuns` (the same
run bookkeeping and predictor core as the line predictor) and, when the core
decides, back to the bus as a ``StopCommand`` in the same call: no zenoh hop,
no second process, no router between the sample and the stop.

It still publishes on zenoh everything the line predictor publishes
(``events``, ``intensity``, ``decision``, ``results``, ``runs``), through the station's
queued publisher: the CAN thread only queues. It holds the station's
``health/predictor`` token, so ``boltwatch status`` sees the station's
predictor, and a second predictor for the station (a line predictor) is
refused, as two line predictors are.

It hears the station's part on zenoh (``boltwatch/<st>/part``: the line's
PLC or scanner) in its subscriber's callback, which only sets the station's
current part; a run started on the CAN thread takes the part current then.
A part scan that does not decode, or names another station, is counted as a
bad payload. A part must reach the edge box before its run starts: one
scanned while the box is cut off from the line never arrives, and the runs
go on naming the part before. At start it asks the line for the station's
last part in the background (:mod:`.part_at_start`): the runs before an answer
(or a scan) name none, the ones after name the line's part as ``restored``.

What it counts (samples its core could not use, runs that started again,
part scans refused, ...) goes out once a second as the station's
``PredictorStats``, from a timer thread of its own through the same queue.

It implements the acquisition's ``Decider`` protocol
(``services/acquisition/decider.py``) by shape; the CLI joins the two.
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable

import zenoh

from services.predictor.part_at_start import PartAtStart
from services.predictor.served_station import ServedStation
from services.predictor.station_refusal import refuse_stations_served_elsewhere
from services.predictor.station_runs import StationRuns
from shared.config import LoadedStation
from shared.contract import Sample, StageDecision, StopDecision, ToolState, channels
from shared.errors import InputError
from shared.runtime import RateLimitedLog, ServiceSkeleton

LOG = logging.getLogger(__name__)

#: message -> None (on its channel), never waiting: the station's queued publisher
Publish = Callable[[object], None]
#: how often the station's PredictorStats goes out
STATS_PERIOD_S = 1.0


class EdgePredictor:
    """One station's runs, decided on the calling (CAN) thread."""

    def __init__(self, skeleton: ServiceSkeleton, station: LoadedStation, publish: Publish) -> None:
        """``skeleton``: the acquisition's; the health token is declared through it."""
        refuse_stations_served_elsewhere(skeleton.session, [station.station_id])
        self._runs = StationRuns(ServedStation(station))
        self._publish = publish
        self._log_bad_part = RateLimitedLog(LOG)
        # before the health token: a predictor the line sees alive hears the station's parts
        skeleton.subscriber(channels.PART.key(station.station_id), self._on_part)
        skeleton.health_token(station.station_id, "predictor")
        # the part at the station until a scan is heard: asked of the line, never waited for
        self._part_at_start = PartAtStart(skeleton.session, {station.station_id: self._runs})
        self._started_ns = time.time_ns()
        self._closed = threading.Event()
        self._stats = threading.Thread(
            target=self._publish_stats, name="predictor-stats", daemon=True
        )
        self._stats.start()
        LOG.info(
            "predictor of %s on the acquisition's CAN thread (placement edge)", station.station_id
        )

    def on_tool_state(self, state: ToolState) -> None:
        for message in self._runs.on_tool(state):  # a run's result and summary when it ended
            self._publish(message)

    def on_sample(self, sample: Sample) -> StopDecision | StageDecision | None:
        decision: StopDecision | StageDecision | None = None
        for message in self._runs.on_sample(sample, time.time_ns()):
            if isinstance(message, StopDecision | StageDecision):  # the acquisition sends it
                decision = message
            self._publish(message)
        return decision

    def _on_part(self, sample: zenoh.Sample) -> None:
        """A part scan of the station, on zenoh's receive thread: the current part only."""
        runs = self._runs
        try:
            scan = runs.served.decode_part(sample.payload.to_bytes())
            if scan.station != runs.served.station_id:
                raise InputError(f"it names station {scan.station}")
        except InputError as err:
            runs.counts.bad_payloads += 1  # only this thread counts bad payloads at the edge
            self._log_bad_part(
                "ignored a part scan of %s (#%d): %s",
                runs.served.station_id,
                runs.counts.bad_payloads,
                err,
            )
            return
        runs.on_part(scan)

    @property
    def runs(self) -> StationRuns:
        return self._runs

    def _publish_stats(self) -> None:
        while not self._closed.wait(STATS_PERIOD_S):
            self._publish(self._runs.counts.stats(time.time_ns(), self._started_ns))

    def close(self) -> None:
        """Stop asking the line and the stats thread (its token goes with the acquisition's,
        in its skeleton)."""
        self._part_at_start.close()
        self._closed.set()
        self._stats.join(timeout=5.0)
