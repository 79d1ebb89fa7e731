"""One service's life in one place: what it opens, what it declares, in what order it stops.

Every long-running service (``boltwatch serve rig | acquisition | predictor |
recorder | router``) has the same ``main``: load its configuration, build a
:class:`ServiceSkeleton`, open and declare what it needs through it, and
:meth:`~ServiceSkeleton.run` its work::

    with ServiceSkeleton("acquisition") as skeleton:
        bus = skeleton.device(open_bus(station.config.can))
        session = skeleton.open_session(station.config.zenoh)
        ...
        skeleton.health_token(station_id, "acquisition")
        return skeleton.run(work)

The skeleton owns all of it in one :class:`~contextlib.ExitStack` and stops
it in a fixed order of stages (:class:`Stop`), whatever order the service
declared things in:

1. ``INPUT``: stop taking input (subscribers, queryables, inboxes);
2. ``WORK``: finish the work (last counters, files finished);
3. ``OUTPUT``: flush and undeclare what publishes;
4. ``HEALTH``: undeclare the health tokens (the line now sees the service gone);
5. ``SESSION``: close the zenoh session;
6. ``DEVICE``: close what is outside zenoh (the CAN bus, a Rerun server).

Within one stage the last thing registered is closed first (an ExitStack).
The stages run when the ``with`` block ends: after :meth:`run` has returned,
so the work thread has already ended (or been given up on after its grace).
A close that raises does not keep the later ones from running. Stages that
take longer than :data:`~shared.runtime.stop_deadline.STOP_DEADLINE_S` end the
process, every thread's stack in the log (:mod:`shared.runtime.stop_deadline`).

:meth:`run` is :class:`~shared.runtime.service_runtime.ServiceRunner`: the work in a
thread, SIGINT/SIGTERM on the main thread, exit status 0 or 1.
"""

from __future__ import annotations

import contextlib
import enum
import threading
from collections.abc import Callable
from contextlib import AbstractContextManager
from typing import Any, TypeVar

import zenoh

from shared.config import ZenohSection
from shared.contract import Channel, keys
from shared.runtime.service_runtime import ServiceRunner
from shared.runtime.stop_deadline import StopDeadline, dump_stacks_on_sigusr1
from shared.runtime.zenoh_session import declare_channel, open_from, open_session

T = TypeVar("T")


class Stop(enum.IntEnum):
    """The stages of a service's stop, in the order they run."""

    INPUT = 1
    WORK = 2
    OUTPUT = 3
    HEALTH = 4
    SESSION = 5
    DEVICE = 6


class ServiceSkeleton:
    """The session, health tokens, subscriptions, publishers and stop order of one service."""

    def __init__(self, name: str, session: zenoh.Session | None = None) -> None:
        """``session``: one opened elsewhere that the skeleton now owns (closes at SESSION)."""
        self.name = name
        self._stages = {stage: contextlib.ExitStack() for stage in Stop}
        self._stack = contextlib.ExitStack()
        for stage in sorted(Stop, reverse=True):  # the first stage is closed first
            self._stack.enter_context(self._stages[stage])
        self._session: zenoh.Session | None = None
        self._deadline: StopDeadline | None = None
        if session is not None:
            self.own_session(session)

    def __enter__(self) -> ServiceSkeleton:
        return self

    def __exit__(self, *_exc: object) -> None:
        self.close()

    def close(self) -> None:
        """Run the stop stages in order; safe to call twice."""
        try:
            self._stack.close()
        finally:
            if self._deadline is not None:
                self._deadline.disarm()

    def on_stop(self, stage: Stop, callback: Callable[[], object]) -> None:
        """Call ``callback`` in ``stage`` of the stop."""
        self._stages[stage].callback(callback)

    def device(self, resource: AbstractContextManager[T]) -> T:
        """Enter ``resource`` (a CAN bus): left in the DEVICE stage, after the session."""
        return self._stages[Stop.DEVICE].enter_context(resource)

    # -- the zenoh session ------------------------------------------------------------

    @property
    def session(self) -> zenoh.Session:
        if self._session is None:
            raise RuntimeError(f"{self.name}: no zenoh session opened yet")
        return self._session

    def open_session(self, section: ZenohSection, wait_for_router: bool = True) -> zenoh.Session:
        """The session of a station service (:func:`shared.runtime.zenoh_session.open_session`;
        ``wait_for_router`` False: a spooling service, which starts at once)."""
        return self.own_session(open_session(section, wait_for_router))

    def open_session_from(self, config: zenoh.Config) -> zenoh.Session:
        """A session of a hand-made config (the router's)."""
        return self.own_session(open_from(config))

    def own_session(self, session: zenoh.Session) -> zenoh.Session:
        """Take ``session`` (opened elsewhere): it is closed in the SESSION stage."""
        if self._session is not None:
            raise RuntimeError(f"{self.name}: one service has one zenoh session")
        self._session = session
        self._stages[Stop.SESSION].callback(session.close)
        return session

    # -- what the service declares on it ----------------------------------------------

    def health_token(self, station: str, role: str) -> zenoh.LivelinessToken:
        """``boltwatch/<station>/health/<role>``, undeclared in the HEALTH stage."""
        token = self.session.liveliness().declare_token(keys.health_key(station, role))
        self._stages[Stop.HEALTH].callback(_undeclare, token)
        return token

    def subscriber(
        self, key: str, callback: Callable[[zenoh.Sample], Any]
    ) -> zenoh.Subscriber[None]:
        """A subscriber calling ``callback`` per sample, undeclared in the INPUT stage."""
        subscriber = self.session.declare_subscriber(key, callback)
        self._stages[Stop.INPUT].callback(_undeclare, subscriber)
        return subscriber

    def queryable(self, key: str, callback: Callable[[zenoh.Query], Any]) -> zenoh.Queryable[None]:
        """A queryable answering with ``callback``, undeclared in the INPUT stage."""
        queryable = self.session.declare_queryable(key, callback)
        self._stages[Stop.INPUT].callback(_undeclare, queryable)
        return queryable

    def publisher(self, channel: Channel[Any], station: str) -> zenoh.Publisher:
        """A publisher of ``channel`` for ``station`` with the channel's options (its row in
        :mod:`shared.contract.channels`), undeclared in the OUTPUT stage."""
        publisher = declare_channel(self.session, channel, station)
        self._stages[Stop.OUTPUT].callback(_undeclare, publisher)
        return publisher

    # -- running ----------------------------------------------------------------------

    def run(
        self,
        work: Callable[[threading.Event], None],
        wake: Callable[[], None] = lambda: None,
        grace_s: float = 5.0,
    ) -> int:
        """``work(stop)`` in a thread until it returns or SIGINT/SIGTERM; 0 clean, 1 failed
        (:class:`~shared.runtime.service_runtime.ServiceRunner`). The stop stages run after, when
        the ``with`` block ends, within a deadline (:mod:`shared.runtime.stop_deadline`)."""
        dump_stacks_on_sigusr1()
        try:
            return ServiceRunner(self.name, work, wake, grace_s).run()
        finally:
            self._deadline = StopDeadline(self.name)


def _undeclare(entity: zenoh.LivelinessToken | zenoh.Subscriber[None] | Any) -> None:
    """Undeclare a zenoh entity; one whose session is already gone is gone too."""
    with contextlib.suppress(zenoh.ZError):
        entity.undeclare()
