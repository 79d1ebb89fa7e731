"""plateau_closest, eqs. 64/65: stop on the plateau closest to the target (per event).

Stop when the next plateau is predicted no closer to the target than the
current one, |F_next - F_target| ≥ |F_now - F_target| (eq. 65). F_now is
measured (the plateau the joint sits on after slip j); F_next = F_now + the
predicted step. Torque-only (eq. 64): T_now and T_next are the predicted
peaks of the current and the next plateau (the peak torque of a plateau is
F · r · μ_stick, so it ranks plateaus like the force does); the core passes
them only when the torque plateau rule is on and the joint climbs a staircase.
"""

from __future__ import annotations

from shared.stickslip.stop_rules.stop import Stop


class PlateauRule:
    """Eq. 65 on a force target; eq. 64 on a torque target."""

    __slots__ = ("_target_force_n", "_target_torque_nm")

    def __init__(self, target_force_n: float | None, target_torque_nm: float | None) -> None:
        self._target_force_n = target_force_n
        self._target_torque_nm = target_torque_nm

    def check(
        self,
        force_now_n: float | None,
        force_next_n: float | None,
        peak_now_nm: float | None,
        peak_next_nm: float | None,
    ) -> Stop | None:
        target_force = self._target_force_n
        if target_force is not None and force_now_n is not None and force_next_n is not None:
            if abs(force_next_n - target_force) >= abs(force_now_n - target_force):
                return Stop(
                    "plateau_closest",
                    f"plateau {force_now_n:.0f} N; next {force_next_n:.0f} N is no closer to "
                    f"{target_force:g} N (eq. 65)",
                    force_next_n,
                )
            return None
        target_torque = self._target_torque_nm
        if (
            target_torque is not None
            and peak_now_nm is not None
            and peak_next_nm is not None
            and abs(peak_next_nm - target_torque) >= abs(peak_now_nm - target_torque)
        ):
            return Stop(
                "plateau_closest",
                f"peak {peak_now_nm:.4g} Nm; next {peak_next_nm:.4g} Nm is no closer to "
                f"{target_torque:g} Nm (eq. 64)",
                peak_next_nm,
            )
        return None
