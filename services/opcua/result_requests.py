"""ResultManagement's ``GetResultById``: a result from the results store, with its trace.

Machinery/Result's method (OPC 40001-101; IJT Base's
``JoiningSystemResultManagementType`` has it) takes ``ResultId`` and
``Timeout`` and gives ``ResultHandle``, ``Result`` and ``Error``. A client asks
it for any result the station's results store holds, not only the newest in
the Results folder, and only this way gets the result's trace (the event and
the folder carry no curves). :func:`result_by_id` (blocking: asyncua runs a
method that is not a coroutine in its thread pool):

- ``ResultId`` ``<station>/<run id>`` of the joining system's station: the
  results store's tightening by its key, with its steps (``StepResults``),
  and the samples of its run from the recording the store names
  (:mod:`.result_trace`; while the recorder still writes it, its flushed part
  under the writing name) as ``Trace``;
- the recording gone, or not on this machine (another host's path), or no
  samples of the run in it: the result without ``Trace``, and
  ``ExtendedMetaData`` ``TraceMissing`` says why;
- ``ResultHandle`` is always 0 (``ReleaseResultHandle`` is not offered: the
  server keeps nothing per client);
- ``Error`` 0, or one of :data:`ERROR_UNKNOWN_RESULT` and
  :data:`ERROR_STORE` (application-specific errors are negative), ``Result``
  then null.
"""

from __future__ import annotations

import logging
from pathlib import Path
from typing import Any

from asyncua import ua

from services.opcua.result_encoding import result_data
from services.opcua.result_trace import recorded_samples, trace_values
from services.opcua.result_values import result_id, result_values
from shared.errors import InputError, StoreError
from shared.recordings import writing_path
from shared.results import ResultsQuery, ResultsStore, StoredResult, StoreTarget

LOG = logging.getLogger(__name__)

#: ``Error`` of GetResultById: no such result of this station in its results store
ERROR_UNKNOWN_RESULT = -1
#: ``Error`` of GetResultById: the results store could not be read
ERROR_STORE = -2
#: ``ResultHandle`` when the server does not keep results per client
NO_HANDLE = 0
APPLICATION = "boltwatch serve opcua"


def stored_by_id(target: StoreTarget, station: str, identifier: str) -> StoredResult | None:
    """The stored tightening whose ResultId is ``identifier``, if it is ``station``'s."""
    prefix, _, run = identifier.rpartition("/")
    if prefix != station or not run.isdigit():
        return None
    query = ResultsQuery(stations=[station], run_id=int(run), limit=1)
    with ResultsStore(target, create=False, application=APPLICATION) as store:
        found = store.find(query)
    return found[0] if found else None


def result_with_trace(stored: StoredResult) -> dict[str, Any]:
    """The result's field values with its trace (or ``TraceMissing`` saying why not)."""
    result = stored.result
    identifier = result_id(result.station, result.run_id)
    trace: dict[str, Any] | None = None
    if stored.recording is None:
        missing = "the results store names no recording of this run"
    else:
        recording = Path(stored.recording)
        if not recording.exists() and writing_path(recording).exists():
            recording = writing_path(recording)  # still written: what was flushed is read
        try:
            samples = recorded_samples(recording, result.station, result.run_id)
        except InputError as err:
            missing = f"recording on {stored.recording_host}: {err}"
        else:
            trace = trace_values(identifier, samples)
            missing = f"no samples of run {result.run_id} in {stored.recording}"
    values = result_values(result, trace)
    if trace is None:
        values["ResultMetaData"]["ExtendedMetaData"]["TraceMissing"] = missing
    return values


def result_by_id(target: StoreTarget, station: str, identifier: str) -> list[ua.Variant]:
    """GetResultById's output arguments (ResultHandle, Result, Error) for ``identifier``."""
    try:
        stored = stored_by_id(target, station, identifier)
    except StoreError as err:
        LOG.warning("GetResultById %s: %s", identifier, err)
        return _outputs(None, ERROR_STORE)
    if stored is None:
        return _outputs(None, ERROR_UNKNOWN_RESULT)
    return _outputs(result_data(result_with_trace(stored)), 0)


def _outputs(result: Any, error: int) -> list[ua.Variant]:
    return [
        ua.Variant(NO_HANDLE, ua.VariantType.UInt32),
        ua.Variant(result, ua.VariantType.ExtensionObject),
        ua.Variant(error, ua.VariantType.Int32),
    ]


def get_result_by_id_method(target: StoreTarget, station: str) -> Any:
    """The callback asyncua links to a joining system's GetResultById."""

    def get_result_by_id(_parent: ua.NodeId, identifier: ua.Variant, *_timeout: Any) -> Any:
        if not isinstance(identifier.Value, str):
            return ua.StatusCode(ua.UInt32(ua.StatusCodes.BadInvalidArgument))
        return result_by_id(target, station, identifier.Value)

    return get_result_by_id
