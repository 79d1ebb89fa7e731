"""``boltwatch serve opcua --config STATION... [--listen opc.tcp://HOST:PORT]``: the line's
OPC UA server for industrial joining.

Loads the station files (the stations served, in their order; the first file's
``[zenoh]`` names the router), checks the security options
(:mod:`.server_security`), and runs, in its work thread, one asyncio loop with
the asyncua server: the models (:mod:`.nodeset_loading`), the delivery of events
to every notifier that sees them and ConditionRefresh (:mod:`.event_delivery`), a
joining system per station (:mod:`.joining_systems`) with its conditions
(:mod:`.alert_conditions`), then each result into it. Once the OPC UA
server listens, the zenoh session is opened (clients may connect and subscribe
before the line's router is there); then results come from
``boltwatch/<st>/results`` (:class:`~.line_inbox.LineInbox`; a multi-spindle
station's cycles' common results from ``boltwatch/<st>/cycles``, each an IJT sync
result of its own: :mod:`.cycle_values`; with the alerts and
alarms, which become the conditions' states: :mod:`.alert_events`; a tool's wear
condition goes off when its wear ledger shows it serviced) and, once
subscribed, the newest :data:`STARTUP_RESULTS` per station from the stations'
results stores (:mod:`shared.results`), oldest first, so a client finds the last
result at once. A result already served (the same ResultId) is not served twice.
Each joining system's ResultManagement methods (GetResultById, GetLatestResult,
GetResultIdListFiltered, ReleaseResultHandle) answer from its station's results
store (:mod:`.result_requests`). The station's tools and their
counters come from its wear ledger (:mod:`.tool_assets`), read again every
:data:`TOOLS_REFRESH_S`, and so does its controller's identification
(:mod:`.controller_assets`). An operator's acknowledgement (confirmation, comment) of
a condition is logged and put on ``boltwatch/<st>/alert/ack`` (:class:`~shared.contract.AlertAck`),
which the line's recorder records.
"""

from __future__ import annotations

import argparse
import asyncio
import logging
import threading
import time
from collections.abc import Sequence
from typing import Any

import zenoh
from asyncua import Server

from services.opcua.alert_conditions import ConditionMethods, StationConditions
from services.opcua.alert_events import alert_event, wear_cleared
from services.opcua.controller_assets import ControllerAsset
from services.opcua.controller_values import ControllerIdentity, controller_identity
from services.opcua.cycle_values import cycle_result_id, cycle_values
from services.opcua.event_delivery import EventDelivery
from services.opcua.joining_systems import JoiningSystem, cycle_browse_name, result_browse_name
from services.opcua.line_inbox import LineInbox
from services.opcua.nodeset_files import nodeset_folder
from services.opcua.nodeset_loading import MACHINERY_RESULT, load_models
from services.opcua.result_encoding import result_data
from services.opcua.result_requests import APPLICATION, result_management_methods
from services.opcua.result_values import result_id, result_values
from services.opcua.served_results import ServedResults
from services.opcua.server_security import SecuritySettings, apply, operators
from services.opcua.system_identification import system_identification
from services.opcua.tool_assets import ToolAssets
from services.opcua.tool_values import ToolCounters, tool_counters
from shared.config import AnyStation, ControllerStation, load_any_line
from shared.contract import AlertAck, CycleResult, TighteningResult, channels, encode
from shared.errors import InputError, StoreError
from shared.recordings import software_version
from shared.results import ResultsQuery, ResultsStore, station_store
from shared.runtime import ServiceSkeleton, exit_now
from shared.wear import BrokenLedgerError, WearLedger, ledger_path

LOG = logging.getLogger(__name__)

#: results per station read from the results store at start
STARTUP_RESULTS = 5
#: how often the loop looks at the inbox and the stop flag, seconds
POLL_S = 0.05
#: how often the tools' counters are read again from the wear ledgers, seconds
TOOLS_REFRESH_S = 2.0
SERVER_NAME = "boltwatch IJT server"
#: its health token, boltwatch/<st>/health/opcua
HEALTH = "opcua"


class OpcuaService:
    """The asyncua server of the stations, fed from zenoh and the results stores."""

    def __init__(
        self,
        stations: Sequence[AnyStation],
        skeleton: ServiceSkeleton,
        listen: str,
        security: SecuritySettings,
    ) -> None:
        self._stations = list(stations)
        self._skeleton = skeleton
        self._listen = listen
        self._security = security
        self._served = {station.station_id: ServedResults() for station in self._stations}
        #: each station's publisher of alert acknowledgements, once the session is open
        self._acks: dict[str, zenoh.Publisher] = {}
        self._version = software_version()

    def work(self, stop: threading.Event) -> None:
        if not LOG.isEnabledFor(logging.DEBUG):  # asyncua logs each node of its own at INFO
            logging.getLogger("asyncua").setLevel(logging.WARNING)
        asyncio.run(self._serve(stop))

    async def _serve(self, stop: threading.Event) -> None:
        server = Server()
        await server.init()
        server.set_endpoint(self._listen)
        server.set_server_name(SERVER_NAME)
        await apply(server, self._security)
        await load_models(server, nodeset_folder())
        delivery = await EventDelivery.create(server)
        condition_methods = ConditionMethods(server, operators(self._security), self._record)
        condition_methods.link_type_methods()
        systems = {
            station.station_id: await JoiningSystem.create(server, station.station_id, delivery)
            for station in self._stations
        }
        conditions = {
            station: await StationConditions.create(server, system, delivery, condition_methods)
            for station, system in systems.items()
        }
        for loaded in self._stations:
            await systems[loaded.station_id].identify(system_identification(loaded))
        result_ns = await server.get_namespace_index(MACHINERY_RESULT)
        for loaded in self._stations:
            system = systems[loaded.station_id]
            methods = result_management_methods(station_store(loaded), system.station, result_ns)
            for name, callback in methods.items():
                server.link_method(await system.result_management_method(name), callback)
        assets = {
            station: await ToolAssets.create(server, station, system.node)
            for station, system in systems.items()
        }
        controllers = {
            station: await ControllerAsset.create(server, station, system.node)
            for station, system in systems.items()
        }
        async with server:
            LOG.info("OPC UA server of %s at %s", ", ".join(systems), self._listen)
            # the line after the server: a client may connect and subscribe before the router
            # is there (the session waits for it, as [zenoh] connect_timeout_s says)
            await asyncio.to_thread(self._skeleton.open_session, self._stations[0].config.zenoh)
            inbox = LineInbox(self._skeleton, list(systems))
            for station in systems:
                self._acks[station] = self._skeleton.publisher(channels.ALERT_ACK, station)
                self._skeleton.health_token(station, HEALTH)
            for stored in await asyncio.to_thread(self._newest):  # after subscribing: no gap
                await self._publish(systems, stored)
            tools_due_s = 0.0
            while not stop.is_set():
                if time.monotonic() >= tools_due_s:
                    for station, (counters, controller) in (
                        await asyncio.to_thread(self._assets)
                    ).items():
                        await assets[station].update(counters)
                        await controllers[station].update(controller)
                        await _clear_serviced(conditions[station], counters)
                    tools_due_s = time.monotonic() + TOOLS_REFRESH_S
                message = inbox.next()
                if message is None:
                    await asyncio.sleep(POLL_S)
                elif isinstance(message, TighteningResult):
                    await self._publish(systems, message)
                elif isinstance(message, CycleResult):
                    await self._publish_cycle(systems, message)
                else:
                    alert = alert_event(message)
                    await conditions[alert.station].report(alert)
                    LOG.info("%s alert: %s", alert.station, alert.text)

    async def _publish(self, systems: dict[str, JoiningSystem], result: TighteningResult) -> None:
        identifier = result_id(result.station, result.run_id)
        await self._serve_once(
            systems.get(result.station),
            identifier,
            result_browse_name(result.run_id),
            result_values(result),
            "result",
            f"{identifier} {result.result}",
        )

    async def _publish_cycle(self, systems: dict[str, JoiningSystem], cycle: CycleResult) -> None:
        """A multi-spindle cycle's common result: an IJT sync result of its own, referring to
        its spindles' results (:mod:`.cycle_values`)."""
        identifier = cycle_result_id(cycle.station, cycle.sync_id)
        await self._serve_once(
            systems.get(cycle.station),
            identifier,
            cycle_browse_name(cycle.sync_id),
            cycle_values(cycle),
            "cycle result",
            f"{identifier} {cycle.result}",
        )

    async def _serve_once(
        self,
        system: JoiningSystem | None,
        identifier: str,
        browse_name: str,
        values: dict[str, Any],
        kind: str,
        message: str,
    ) -> None:
        """A result into its station's joining system, once per ResultId (a station this
        server does not serve: nothing)."""
        if system is None:
            return
        if not self._served[system.station].first_time(identifier):
            return
        await system.publish(identifier, browse_name, result_data(values), message)
        LOG.info("%s %s served", kind, message)

    async def _record(self, ack: AlertAck) -> None:
        """An acknowledgement (confirmation, comment) of an alert: logged, and put on the line
        (``boltwatch/<st>/alert/ack``) for the recorder."""
        LOG.info(
            "%s: %s %s by %s (%s)%s",
            ack.station,
            ack.condition_name,
            ack.action,
            ack.user or "an anonymous session",
            ack.client or "no application URI",
            f": {ack.comment}" if ack.comment else "",
        )
        publisher = self._acks.get(ack.station)
        if publisher is None:  # no alert comes before the session; said in case
            LOG.warning("%s: not put on the line: no zenoh session yet", ack.station)
            return
        try:
            await asyncio.to_thread(publisher.put, encode(ack))
        except zenoh.ZError as err:  # the session closing
            LOG.warning(
                "%s: %s %s not put on the line: %s", ack.station, ack.condition, ack.action, err
            )

    def _assets(self) -> dict[str, tuple[list[ToolCounters], ControllerIdentity]]:
        """Each station's tools in its wear ledger (none while it has no ledger), and its
        controller; a station whose ledger cannot be read now is left out (its figures stay as
        they were)."""
        found: dict[str, tuple[list[ToolCounters], ControllerIdentity]] = {}
        for station in self._stations:
            path = ledger_path(station.recordings_folder)
            threshold = station.config.recorder.wear_service_threshold
            tools = []
            if path.exists():
                try:
                    with WearLedger(path, read_only=True) as ledger:
                        tools = ledger.tools(station=station.station_id)
                except (InputError, BrokenLedgerError) as err:
                    LOG.debug("no tools of %s from %s now: %s", station.station_id, path, err)
                    continue
            found[station.station_id] = (
                [tool_counters(tool, threshold) for tool in tools],
                controller_identity(isinstance(station, ControllerStation), tools, self._version),
            )
        return found

    def _newest(self) -> list[TighteningResult]:
        """The newest results of each station in its results store, oldest first."""
        found: list[TighteningResult] = []
        for station in self._stations:
            target = station_store(station)
            query = ResultsQuery(stations=[station.station_id], limit=STARTUP_RESULTS)
            try:
                with ResultsStore(target, create=False, application=APPLICATION) as store:
                    found.extend(reversed([stored.result for stored in store.find(query)]))
            except StoreError as err:
                LOG.info("no results of %s from %s yet: %s", station.station_id, target, err)
        return found


async def _clear_serviced(conditions: StationConditions, counters: list[ToolCounters]) -> None:
    """A tool's wear condition goes off when the ledger shows it below its threshold (it was
    serviced), or shows no threshold any more."""
    by_tool = {tool.tool_id: tool for tool in counters}
    for key in conditions.active_keys():
        source, _, tool_id = key.partition("/")
        tool = by_tool.get(int(tool_id)) if source == "wear" else None
        if tool is None:
            continue
        threshold = tool.intensity_threshold
        if threshold is None or tool.intensity_since_service < threshold:
            await conditions.report(
                wear_cleared(
                    conditions.station,
                    tool.tool_id,
                    time.time_ns(),
                    tool.intensity_since_service,
                    threshold if threshold is not None else 0.0,
                )
            )


def main(args: argparse.Namespace) -> int:
    stations = load_any_line(args.config)
    security = SecuritySettings(
        certificate=args.certificate,
        private_key=args.private_key,
        trusted_clients=args.trusted_clients,
        users=args.users,
        anonymous_read_only=args.anonymous_read_only,
    )
    security.check()
    with ServiceSkeleton("opcua") as skeleton:
        service = OpcuaService(stations, skeleton, args.listen, security)
        status = skeleton.run(service.work)
    exit_now(status)  # the session is closed: no finalisation for a late zenoh thread to abort
