"""A controller's run as a TighteningResult: OK only where the controller and the windows agree."""

from __future__ import annotations

import pytest

from shared.contract import ControllerFunction, ControllerResult, ControllerStep
from shared.quality import SAID_OK_WINDOWS_NOK, controller_result


def run(said: str, torque_nm: float, step_result: str | None = None) -> ControllerResult:
    functions = [
        ControllerFunction("TF Torque", 200.0, torque_nm),
        ControllerFunction("MF TorqueMin", 100.0, torque_nm),
        ControllerFunction("MF TorqueMax", 250.0, torque_nm),
    ]
    step = ControllerStep("Tightening", step_result or said, "", 0, functions)
    return ControllerResult(
        "op1", 7, 11, 1, 1_700_000_000_000_000_000, said, "", "", "Nm",
        None, None, None, None, None, None, None, None, None, [step],
    )  # fmt: skip


@pytest.mark.parametrize(
    ("said", "torque_nm", "result", "reasons"),
    [
        ("OK", 200.0, "OK", ""),
        (
            "OK",
            9999.99,
            "NOK",
            f"{SAID_OK_WINDOWS_NOK}; torque high: 9999.99 Nm, window 100 to 250 Nm",
        ),
        (
            "NOK",
            9999.99,
            "NOK",
            "step 'Tightening' NOK; torque high: 9999.99 Nm, window 100 to 250 Nm",
        ),
        ("NOK", 200.0, "NOK", "step 'Tightening' NOK"),
        ("", 50.0, "NOK", "torque low: 50 Nm, window 100 to 250 Nm"),
    ],
)
def test_the_result_is_ok_only_where_the_controller_and_the_windows_agree(
    said: str, torque_nm: float, result: str, reasons: str
) -> None:
    """Before: the controller's OK was the result whatever the windows said, beside a NOK
    reason "torque high"."""
    made = controller_result(run(said, torque_nm), None, "", "controller")
    assert (made.result, made.nok_reasons) == (result, reasons)


def test_a_controller_nok_without_a_step_or_a_window_says_so() -> None:
    made = controller_result(run("NOK", 200.0, step_result="OK"), None, "", "import")
    assert (made.result, made.nok_reasons) == ("NOK", "the controller said NOK")


def test_an_ok_with_a_step_nok_is_nok_naming_both() -> None:
    made = controller_result(run("OK", 200.0, step_result="NOK"), None, "", "import")
    assert made.result == "NOK"
    assert made.nok_reasons == "the controller said OK, a step NOK; step 'Tightening' NOK"


def test_the_stations_window_is_judged_where_it_has_a_bound() -> None:
    made = controller_result(
        run("OK", 200.0), None, "", "controller", windows={"torque": (150.0, 190.0)}
    )
    assert (made.final_torque_nm.min, made.final_torque_nm.max) == (150.0, 190.0)
    assert made.final_torque_nm.status == "high" and made.result == "NOK"
    same = controller_result(
        run("OK", 200.0), None, "", "controller", windows={"torque": (None, None)}
    )
    assert (same.final_torque_nm.min, same.final_torque_nm.max, same.result) == (100.0, 250.0, "OK")
