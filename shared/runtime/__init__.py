"""(to be written)"""

from shared.runtime.can_bus import open_bus
from shared.runtime.log_limit import RateLimitedLog
from shared.runtime.logging_setup import setup_logging
from shared.runtime.option_types import float_in, int_in, port_number, seconds
from shared.runtime.queued_publisher import QueuedPublisher
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
    "float_in",
    "follow_supervisor",
    "int_in",
    "keep_thread_state",
    "open_bus",
    "open_from",
    "open_session",
    "port_number",
    "seconds",
    "setup_logging",
    "supervisor_environment",
    "use_one_receive_thread",
    "use_realtime_priority",
    "zenoh_config",
    "zenoh_reason",
]
