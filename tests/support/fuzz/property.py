"""The property a live service keeps under hostile payloads, for the tests and the long run.

Per example, a few payloads are drawn for one channel (:mod:`.payloads`):
now and then a message with an extreme value first, then one to three that
must be refused; they are sent to the target (:mod:`.targets`) and, once the
service has handled them, it must be alive and have counted exactly the
refused ones (an extreme counts as refused where the service's own rules
say so: :mod:`.rules`). After the examples the caller proves the
service still serves (``prove_serving``).
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from tests.support.fuzz.payloads import Extreme, extremes, refused, template
from tests.support.fuzz.rules import ServiceRules

#: channel -> its refused payloads, its extremes
Channels = dict[str, tuple[st.SearchStrategy[bytes], st.SearchStrategy[Extreme]]]


def channels_of(
    station: str,
    topics: tuple[str, ...],
    extra_refused: Callable[[str, Any], list[bytes]] | None = None,
) -> Channels:
    """The strategies of each topic's channel at ``station``; ``extra_refused(topic,
    message)``: payloads this service refuses by its own rules, beyond the contract's."""
    now_ns = time.time_ns()
    out: Channels = {}
    for topic in topics:
        message = template(topic, station, now_ns)
        extra = extra_refused(topic, message) if extra_refused is not None else None
        out[topic] = (refused(message, extra), extremes(message))
    return out


@dataclass
class FuzzCount:
    """What one run of the property sent."""

    examples: int = 0
    refused: int = 0
    valid: int = 0


def fuzz(target: Any, rules: ServiceRules, examples: int) -> FuzzCount:
    """Run the property for ``examples`` examples on every channel of ``target``;
    AssertionError (via hypothesis) when the service died, missed a refusal or counted
    a valid message as refused."""
    channels = channels_of(target.station, target.channels, rules.extra_refused)
    refuses_extreme = rules.refuses_extreme
    count = FuzzCount()

    @settings(
        max_examples=examples,
        deadline=None,
        database=None,
        suppress_health_check=list(HealthCheck),
    )
    @given(st.data())
    def feed(data: st.DataObject) -> None:
        channel = data.draw(st.sampled_from(sorted(channels)), label="channel")
        bad, edges = channels[channel]
        for field, value, payload in data.draw(st.lists(edges, max_size=1), label="extreme"):
            refuse = refuses_extreme(channel, field, value)
            target.send(channel, payload, refuse=refuse)
            count.refused += refuse
            count.valid += not refuse
        payloads = data.draw(st.lists(bad, min_size=1, max_size=3), label="refused")
        for payload in payloads:  # last: once they are counted, what came before was handled
            target.send(channel, payload, refuse=True)
        target.wait_handled()
        assert target.alive(), "the service died"
        assert target.refused() == target.refusals, (target.refused(), target.refusals)
        count.examples += 1
        count.refused += len(payloads)

    feed()
    return count
