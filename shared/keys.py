"""Zenoh key expressions of boltwatch, in one place.

Every station lives under ``boltwatch/<station>/``:

=========================  ===========================  =================================
key                        publisher                    payload (see :mod:`shared.messages`)
=========================  ===========================  =================================
``samples``                acquisition                  :class:`Sample`, one per 1 kHz sample
                                                        (placement line: the line predictor's)
``sample_batches``         acquisition                  :class:`SampleBatch`, every 10 ms
                                                        (placement edge: what the line records)
``tool``                   acquisition                  :class:`ToolState`, on every change
``bus``                    acquisition                  :class:`BusStats`, once a second
``events``                 predictor                    :class:`StickSlipEvent`
``intensity``              predictor                    :class:`Intensity`
``decision``               predictor                    :class:`StopDecision`
``runs``                   predictor                    :class:`RunSummary`, one per run
``recorder``               recorder                     :class:`RecorderStats`, once a second
``predictor``              predictor                    :class:`PredictorStats`, once a second
``controller``             import (a controller bridge) :class:`ControllerResult`, one per run
``wear``                   recorder (queryable)         wear ledger rows
``health/<service>``       every service (liveliness)   -
=========================  ===========================  =================================

A station's samples go toward the line once, on one of the two channels: one message per sample
where a line predictor decides on them (``[predictor] placement = "line"``), in batches otherwise
(the decision is taken on the station; the line only records them).

``tool``, ``bus``, ``recorder``, ``predictor`` and ``controller`` are additions to DESIGN.md's list:
services need run boundaries, bus fault counters, recorder and predictor health, and a plant needs
its tool controllers' own results (OK/NOK, each step's values); none of those is a sample
or a run summary.
"""

from __future__ import annotations

ROOT = "boltwatch"

SAMPLES = "samples"
SAMPLE_BATCHES = "sample_batches"
TOOL = "tool"
BUS = "bus"
EVENTS = "events"
INTENSITY = "intensity"
DECISION = "decision"
RUNS = "runs"
RECORDER = "recorder"
PREDICTOR = "predictor"
CONTROLLER = "controller"
WEAR = "wear"
HEALTH = "health"

EVERYTHING = f"{ROOT}/**"
#: One chunk below every station: samples, tool, bus, events, ... (not health/*).
ALL_STATION_TOPICS = f"{ROOT}/*/*"


def station_key(station: str, topic: str) -> str:
    """``boltwatch/<station>/<topic>``."""
    return f"{ROOT}/{station}/{topic}"


def health_key(station: str, service: str) -> str:
    """Liveliness token key of ``service`` at ``station``."""
    return f"{ROOT}/{station}/{HEALTH}/{service}"


def split_key(key: str) -> tuple[str, str]:
    """``boltwatch/st1/samples`` -> ``("st1", "samples")``; ``health/x`` keeps its tail.

    Raises ValueError for keys outside ``boltwatch/<station>/...``.
    """
    parts = key.split("/", 2)
    if len(parts) != 3 or parts[0] != ROOT or not parts[1]:
        raise ValueError(f"not a boltwatch station key: {key!r}")
    return parts[1], parts[2]
