"""How a service lives and talks: its skeleton, its zenoh session, its publishers, its CAN bus.

- :mod:`.service_skeleton` (what a service opens and declares, and the order it
  stops in), :mod:`.service_runtime` (signals, the work thread, the exit status),
  :mod:`.supervisor_link` (stop when ``boltwatch up`` dies), :mod:`.stop_deadline`
  (a stop that hangs ends the process, its threads' stacks logged; stacks on SIGUSR1)
- :mod:`.zenoh_session` (sessions from configuration, the router link watched,
  a channel's publisher), :mod:`.receive_threads` (cheap callbacks on zenoh's threads)
- :mod:`.queued_publisher` (publishing without waiting, in order, per station),
  :mod:`.sample_batching` (samples toward the line in batches)
- :mod:`.can_bus` (the station's CAN bus, python-can), :mod:`.realtime` (real-time
  scheduling of the stop path's threads)
- :mod:`.logging_setup` (one line per event, JSON in containers), :mod:`.log_limit`
  (one log line for a flood of alike faults)
- :mod:`.process_exit` (a process ended without the interpreter's finalisation, once
  everything is closed)
"""

from shared.runtime.can_bus import open_bus
from shared.runtime.log_limit import RateLimitedLog
from shared.runtime.logging_setup import setup_logging
from shared.runtime.process_exit import exit_now
from shared.runtime.queued_publisher import QueuedPublisher, station_spool
from shared.runtime.realtime import RIG_PRIORITY, STOP_PATH_PRIORITY, use_realtime_priority
from shared.runtime.receive_threads import keep_thread_state, use_one_receive_thread
from shared.runtime.sample_batching import BATCH_PERIOD_S, MAX_BATCH_SAMPLES, SampleBatching
from shared.runtime.service_skeleton import ServiceSkeleton, Stop
from shared.runtime.supervisor_link import (
    SUPERVISOR_PID_ENV,
    follow_supervisor,
    supervisor_environment,
)
from shared.runtime.zenoh_session import (
    RouterLink,
    TlsFiles,
    client_config,
    declare_channel,
    open_from,
    open_session,
    section_config,
    zenoh_config,
    zenoh_reason,
)

__all__ = [
    "BATCH_PERIOD_S",
    "MAX_BATCH_SAMPLES",
    "RIG_PRIORITY",
    "STOP_PATH_PRIORITY",
    "SUPERVISOR_PID_ENV",
    "QueuedPublisher",
    "RateLimitedLog",
    "RouterLink",
    "SampleBatching",
    "ServiceSkeleton",
    "Stop",
    "TlsFiles",
    "client_config",
    "declare_channel",
    "exit_now",
    "follow_supervisor",
    "keep_thread_state",
    "open_bus",
    "open_from",
    "open_session",
    "section_config",
    "setup_logging",
    "station_spool",
    "supervisor_environment",
    "use_one_receive_thread",
    "use_realtime_priority",
    "zenoh_config",
    "zenoh_reason",
]
