"""ResultManagement's methods, answered from the station's results store.

Machinery/Result's methods (OPC 40001-101, 7.1; IJT Base's
``JoiningSystemResultManagementType`` has them), each linked to a joining system by
:func:`result_management_methods` (blocking callbacks: asyncua runs a method that is
not a coroutine in its thread pool). A client asks them for any result the
station's results store holds, not only the newest in the Results folder, and only
this way gets the result's trace (the event and the folder carry no curves):

- ``GetResultById(ResultId, Timeout)`` gives ``ResultHandle``, ``Result`` and
  ``Error``: the store's tightening of ResultId ``<station>/<run id>`` (the joining
  system's station only), with its steps (``StepResults``) and the samples of
  its run from the recording the store names (:mod:`.result_trace`; while the
  recorder still writes it, its flushed part under the writing name) as
  ``Trace``. The recording gone, or not on this machine (another host's path), or
  no samples of the run in it: the result without ``Trace``, and
  ``ExtendedMetaData`` ``TraceMissing`` says why. A multi-spindle cycle's ResultId
  ``<station>/cycle/<sync id>``: its common result from the store's cycles (the
  sync result of :mod:`.cycle_values`, referring to its spindles' results).
- ``GetLatestResult(Timeout)``: the same of the station's newest result in the
  store (the newest end of a run), trace included (the method has no argument to
  leave it out, and a client of this method alone has no other way to the curves).
- ``GetResultIdListFiltered(Filter, OrderedBy, MaxResults, Timeout)`` gives
  ``ResultHandle``, ``ResultIdList`` and ``Error``: the ResultIds of the station's
  results the filter matches (:mod:`.result_filter`), newest first, at most
  ``MaxResults`` (0: no maximum) and at most :data:`MAX_RESULT_IDS` in one answer.
- ``ReleaseResultHandle(ResultHandle)`` gives ``Error``: the server keeps nothing
  per client, every handle it gives is 0 (:data:`NO_HANDLE`) and releasing it is
  done at once (``Error`` 0); another handle was never given (:data:`ERROR_UNKNOWN_HANDLE`).

``Timeout`` is a hint the server has no use for (it keeps no result for a
client). ``Error`` is 0 or one of the application-specific (negative) codes below,
``Result`` then null; an argument missing, one too many or of the wrong type is
the call's ``Bad_ArgumentsMissing``, ``Bad_TooManyArguments`` or
``Bad_InvalidArgument`` (that argument's ``Bad_TypeMismatch``), and a filter the
store cannot answer ``Bad_InvalidArgument`` with the filter's code
(:class:`~.result_filter.UnsupportedFilterError`).
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path
from typing import Any

from asyncua import ua
from asyncua.ua.ua_binary import struct_from_binary

from services.opcua.cycle_values import cycle_values, parse_cycle_result_id
from services.opcua.result_encoding import result_data
from services.opcua.result_filter import UnsupportedFilterError, filtered_query
from services.opcua.result_trace import recorded_samples, trace_values
from services.opcua.result_values import parse_result_id, result_id, result_values
from shared.errors import InputError, StoreError
from shared.recordings import writing_path
from shared.results import ResultsQuery, ResultsStore, StoredResult, StoreTarget

LOG = logging.getLogger(__name__)

#: ``Error``: no such result of this station in its results store (GetLatestResult: none yet)
ERROR_UNKNOWN_RESULT = -1
#: ``Error``: the results store could not be read
ERROR_STORE = -2
#: ``Error`` of GetResultIdListFiltered: more results match than one answer holds; the list
#: holds the first :data:`MAX_RESULT_IDS` in the order asked (ask again with a narrower
#: CreationTime for the rest)
ERROR_TOO_MANY = -3
#: ``Error`` of ReleaseResultHandle: a handle this server never gave
ERROR_UNKNOWN_HANDLE = -4
#: ``ResultHandle`` when the server does not keep results per client
NO_HANDLE = 0
#: ResultIds in one answer of GetResultIdListFiltered at most (about 20 bytes each)
MAX_RESULT_IDS = 10_000
APPLICATION = "boltwatch serve opcua"
_RELATIVE_PATH_ENCODING = ua.NodeId(ua.Int32(ua.ObjectIds.RelativePath_Encoding_DefaultBinary))


def _id_query(station: str, identifier: str) -> ResultsQuery | None:
    """The query of the tightening whose ResultId is ``identifier``, if it is ``station``'s
    (None: no tightening of the station has it)."""
    parsed = parse_result_id(identifier)
    if parsed is None or parsed[0] != station:
        return None
    return ResultsQuery(stations=[station], run_id=parsed[1], limit=1)


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
    """GetResultById's output arguments (ResultHandle, Result, Error) for ``identifier``
    (a tightening's or a multi-spindle cycle's)."""
    cycle = parse_cycle_result_id(identifier)
    if cycle is not None:
        return _cycle_result(target, station, cycle, f"GetResultById {identifier}")
    query = _id_query(station, identifier)
    return _one_result(target, query, f"GetResultById {identifier}")


def _cycle_result(
    target: StoreTarget, station: str, cycle: tuple[str, int], asked: str
) -> list[ua.Variant]:
    """(ResultHandle, Result, Error) of a cycle's common result (:mod:`.cycle_values`)."""
    if cycle[0] != station:
        return _result_outputs(None, ERROR_UNKNOWN_RESULT)
    try:
        with ResultsStore(target, create=False, application=APPLICATION) as store:
            found = store.cycle(station, cycle[1])
    except StoreError as err:
        LOG.warning("%s: %s", asked, err)
        return _result_outputs(None, ERROR_STORE)
    if found is None:
        return _result_outputs(None, ERROR_UNKNOWN_RESULT)
    return _result_outputs(result_data(cycle_values(found)), 0)


def latest_result(target: StoreTarget, station: str) -> list[ua.Variant]:
    """GetLatestResult's output arguments (ResultHandle, Result, Error): the station's newest."""
    query = ResultsQuery(stations=[station], limit=1)
    return _one_result(target, query, f"GetLatestResult of {station}")


def _one_result(target: StoreTarget, query: ResultsQuery | None, asked: str) -> list[ua.Variant]:
    """(ResultHandle, Result, Error) of the tightening ``query`` finds first, with its trace
    (None: none can match, the store is not opened); ``asked``: the call, for the log."""
    if query is None:
        return _result_outputs(None, ERROR_UNKNOWN_RESULT)
    try:
        with ResultsStore(target, create=False, application=APPLICATION) as store:
            found = store.find(query)
    except StoreError as err:
        LOG.warning("%s: %s", asked, err)
        return _result_outputs(None, ERROR_STORE)
    if not found:
        return _result_outputs(None, ERROR_UNKNOWN_RESULT)
    return _result_outputs(result_data(result_with_trace(found[0])), 0)


def result_ids(
    target: StoreTarget,
    station: str,
    query: ResultsQuery | None,
    max_results: int,
    most: int = MAX_RESULT_IDS,
) -> list[ua.Variant]:
    """GetResultIdListFiltered's output arguments (ResultHandle, ResultIdList, Error) of
    ``query`` (None: nothing matches), at most ``max_results`` (0: no maximum) and ``most``."""
    wanted = most + 1 if max_results == 0 else min(max_results, most + 1)
    found: list[tuple[str, int]] = []
    if query is not None:
        try:
            with ResultsStore(target, create=False, application=APPLICATION) as store:
                found = store.keys(replace(query, limit=wanted))
        except StoreError as err:
            LOG.warning("GetResultIdListFiltered of %s: %s", station, err)
            return _id_outputs([], ERROR_STORE)
    error = ERROR_TOO_MANY if len(found) > most else 0
    return _id_outputs([result_id(*key) for key in found[:most]], error)


def _result_outputs(result: Any, error: int) -> list[ua.Variant]:
    return [
        ua.Variant(NO_HANDLE, ua.VariantType.UInt32),
        ua.Variant(result, ua.VariantType.ExtensionObject),
        ua.Variant(error, ua.VariantType.Int32),
    ]


def _id_outputs(identifiers: list[str], error: int) -> list[ua.Variant]:
    return [
        ua.Variant(NO_HANDLE, ua.VariantType.UInt32),
        ua.Variant(identifiers, ua.VariantType.String, is_array=True),
        ua.Variant(error, ua.VariantType.Int32),
    ]


def _is_int(value: Any) -> bool:
    return isinstance(value, int) and not isinstance(value, bool)


def _is_count(value: Any) -> bool:
    return _is_int(value) and value >= 0


def _is_filter(value: Any) -> bool:
    """A ContentFilter, or null (a null ExtensionObject, as asyncua decodes it)."""
    null = isinstance(value, ua.ExtensionObject) and value.Body is None
    return value is None or null or isinstance(value, ua.ContentFilter)


def _is_paths(value: Any) -> bool:
    return value is None or _relative_paths(value) is not None


def _relative_paths(value: Any) -> list[ua.RelativePath] | None:
    """A RelativePath[] argument; None when it is none. asyncua registers no ExtensionObject
    encoding for RelativePath, so each comes as its undecoded body, decoded here."""
    if value is None:
        return []
    if not isinstance(value, list):
        return None
    paths = []
    for item in value:
        if isinstance(item, ua.RelativePath):
            paths.append(item)
        elif (
            isinstance(item, ua.ExtensionObject)
            and item.TypeId == _RELATIVE_PATH_ENCODING
            and isinstance(item.Body, bytes)
        ):
            try:
                paths.append(struct_from_binary(ua.RelativePath, ua.utils.Buffer(item.Body)))
            except (ua.UaError, ValueError, TypeError):  # a body that is no RelativePath's
                return None
        else:
            return None
    return paths


def _is_text(value: Any) -> bool:
    return isinstance(value, str)


def _status(code: int) -> ua.StatusCode:
    return ua.StatusCode(ua.UInt32(code))


def _refusal(count: int, argument: int, status: int) -> ua.CallMethodResult:
    """The call's Bad_InvalidArgument, ``status`` for input argument ``argument``."""
    good = _status(ua.StatusCodes.Good)
    return ua.CallMethodResult(
        StatusCode=_status(ua.StatusCodes.BadInvalidArgument),
        InputArgumentResults=[
            _status(status) if index == argument else good for index in range(count)
        ],
    )


def _checked(
    arguments: tuple[Any, ...], *kinds: Callable[[Any], bool]
) -> list[Any] | ua.CallMethodResult | ua.StatusCode:
    """The values of ``arguments`` (Variants), each as its ``kinds`` check wants; or the
    call's refusal (asyncua checks neither their count nor their types)."""
    if len(arguments) < len(kinds):
        return _status(ua.StatusCodes.BadArgumentsMissing)
    if len(arguments) > len(kinds):
        return _status(ua.StatusCodes.BadTooManyArguments)
    values = [argument.Value for argument in arguments]
    for index, (value, kind) in enumerate(zip(values, kinds, strict=True)):
        if not kind(value):
            return _refusal(len(kinds), index, ua.StatusCodes.BadTypeMismatch)
    return values


def result_management_methods(
    target: StoreTarget, station: str, result_ns: int
) -> dict[str, Callable[..., Any]]:
    """The callbacks asyncua links to a joining system's ResultManagement methods, by their
    browse names; ``result_ns``: Machinery/Result's namespace index (filter paths)."""

    def get_result_by_id(_parent: ua.NodeId, *arguments: ua.Variant) -> Any:
        values = _checked(arguments, _is_text, _is_int)
        if not isinstance(values, list):
            return values
        return result_by_id(target, station, values[0])

    def get_latest_result(_parent: ua.NodeId, *arguments: ua.Variant) -> Any:
        values = _checked(arguments, _is_int)
        if not isinstance(values, list):
            return values
        return latest_result(target, station)

    def get_result_id_list_filtered(_parent: ua.NodeId, *arguments: ua.Variant) -> Any:
        values = _checked(arguments, _is_filter, _is_paths, _is_count, _is_int)
        if not isinstance(values, list):
            return values
        content_filter, ordered_by, max_results, _timeout = values
        if not isinstance(content_filter, ua.ContentFilter):
            content_filter = None  # null: every result
        ordered_by = _relative_paths(ordered_by)
        try:
            query = filtered_query(station, content_filter, ordered_by, result_ns)
        except UnsupportedFilterError as err:
            LOG.info("GetResultIdListFiltered of %s refused: %s", station, err)
            return _refusal(len(values), err.argument, err.status)
        return result_ids(target, station, query, max_results)

    def release_result_handle(_parent: ua.NodeId, *arguments: ua.Variant) -> Any:
        values = _checked(arguments, _is_count)
        if not isinstance(values, list):
            return values
        error = 0 if values[0] == NO_HANDLE else ERROR_UNKNOWN_HANDLE
        return [ua.Variant(error, ua.VariantType.Int32)]

    return {
        "GetResultById": get_result_by_id,
        "GetLatestResult": get_latest_result,
        "GetResultIdListFiltered": get_result_id_list_filtered,
        "ReleaseResultHandle": release_result_handle,
    }
