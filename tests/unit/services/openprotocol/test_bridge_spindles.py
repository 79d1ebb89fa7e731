"""A multi-spindle system over Open Protocol: the simulated controller of three spindles on
real TCP, the bridge publishing on real zenoh. Each spindle's tightening (0061 with its
channel and the cycle's sync id, its 0900 curves) is a run of its own, of its own tool, with
its spindle and sync id; each cycle (0101, subscribed at the highest revision, 5; 0091 too)
is one common result naming its spindles' runs. A controller of one spindle is subscribed
to neither."""

from __future__ import annotations

from collections import defaultdict
from pathlib import Path

import zenoh

from tests.support.bridge_harness import RunningBridge
from tests.support.listener import Listener
from tests.support.live_recorder import wait_until
from tests.support.simulated_controller import running_controller, write_controller_station

SPINDLES = 3
CYCLES = 2


def test_each_spindle_is_a_run_and_each_cycle_one_common_result(
    tmp_path: Path, sessions: tuple[zenoh.Session, zenoh.Session]
) -> None:
    served, feeding = sessions
    path = write_controller_station(tmp_path)
    path.write_text(
        path.read_text().replace(
            "has_force_sensor = true", f"has_force_sensor = true\nspindles = {SPINDLES}"
        )
    )
    heard = Listener(served, samples_from_batches=True)
    with running_controller(path, runs=CYCLES, wait_for_integrator=True) as controller:
        bridge = RunningBridge(path, feeding)
        try:
            wait_until(lambda: len(heard.of("cycles")) == CYCLES, "every cycle's result")
            links = list(controller.server._links.values())
        finally:
            bridge.finish()
    heard.close()
    results = heard.of("results")
    assert len(results) == SPINDLES * CYCLES
    by_sync: dict[int | None, list] = defaultdict(list)
    for result in results:
        by_sync[result.sync_id].append(result)
    assert len(by_sync) == CYCLES
    for runs in by_sync.values():
        assert sorted(r.spindle for r in runs) == [1, 2, 3]
        assert sorted(r.tool_id for r in runs) == [7, 8, 9]  # each spindle its own tool
        assert len({r.part_id for r in runs}) == 1  # one part a cycle
    summaries = {s.run_id: s for s in heard.of("runs")}
    assert {(r.run_id, r.spindle) for r in results} == {
        (s.run_id, s.spindle) for s in summaries.values()
    }
    for cycle in heard.of("cycles"):
        assert cycle.source == "controller" and cycle.result == "OK"
        mine = {r.spindle: r.run_id for r in by_sync[cycle.sync_id]}
        assert [(s.spindle, s.run_id, s.result) for s in cycle.spindles] == [
            (k, mine[k], "OK") for k in (1, 2, 3)
        ]
    samples: dict[int, int] = defaultdict(int)
    for sample in heard.of("samples"):
        samples[sample.run_id] += 1
    assert all(samples[r.run_id] == summaries[r.run_id].samples > 100 for r in results)
    assert bridge.counts.controller_errors == 0
    assert [(link.cycle_result_revision, link.cycle_status_subscribed) for link in links] == [
        (5, True)
    ]


def test_a_controller_of_one_spindle_is_asked_for_no_cycle(
    tmp_path: Path, sessions: tuple[zenoh.Session, zenoh.Session]
) -> None:
    served, feeding = sessions
    path = write_controller_station(tmp_path)
    heard = Listener(served, samples_from_batches=True)
    with running_controller(path, runs=1, wait_for_integrator=True) as controller:
        bridge = RunningBridge(path, feeding)
        try:
            wait_until(lambda: len(heard.of("runs")) == 1, "the run")
            links = list(controller.server._links.values())
        finally:
            bridge.finish()
    heard.close()
    (result,) = heard.of("results")
    assert (result.spindle, result.sync_id) == (None, None)
    assert heard.of("cycles") == [] and bridge.counts.controller_errors == 0
    assert [(link.cycle_result_revision, link.cycle_status_subscribed) for link in links] == [
        (None, False)
    ]
