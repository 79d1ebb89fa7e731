"""Each result is served once, and the ids kept as served stay bounded."""

from __future__ import annotations

import pytest

from services.opcua.served_results import SERVED_IDS_KEPT, ServedResults


def test_a_result_id_is_served_once() -> None:
    served = ServedResults()
    assert served.first_time("st1/7")
    assert not served.first_time("st1/7")
    assert served.first_time("st1/cycle/7")  # a cycle's id is not its run's


def test_the_oldest_ids_are_forgotten_past_the_bound() -> None:
    served = ServedResults(kept=3)
    for run_id in range(1, 6):
        assert served.first_time(f"st1/{run_id}")
    assert len(served) == 3
    assert not served.first_time("st1/5") and not served.first_time("st1/3")
    assert served.first_time("st1/1")  # forgotten: served again
    assert len(served) == 3


def test_results_past_the_bound_keep_it() -> None:
    served = ServedResults()
    for run_id in range(SERVED_IDS_KEPT + 1000):
        served.first_time(f"st1/{run_id}")
    assert len(served) == SERVED_IDS_KEPT


def test_a_bound_below_one_is_refused() -> None:
    with pytest.raises(ValueError, match="kept is 0, expected at least 1"):
        ServedResults(kept=0)
