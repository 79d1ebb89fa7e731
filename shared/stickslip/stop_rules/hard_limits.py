"""The program's hard limits: torque, force, angle turned (checked on every sample).

A limit fires when it is held for ``limit_samples`` samples in a row: one
spike is not a reason. The torque limit is checked first, then force, then
angle; the first that holds long enough is the stop.
"""

from __future__ import annotations

import math

from shared.stickslip.settings import PredictorSettings
from shared.stickslip.stop_rules.stop import Stop


class HardLimits:
    """torque_limit / force_limit / angle_limit, each counted in samples in a row."""

    __slots__ = (
        "_max_angle",
        "_max_force",
        "_max_torque",
        "_need",
        "_over_angle",
        "_over_force",
        "_over_torque",
    )

    def __init__(self, settings: PredictorSettings) -> None:
        s = settings
        self._need = s.limit_samples
        self._max_torque = s.max_torque_nm if s.max_torque_nm is not None else math.inf
        self._max_force = s.max_force_n if s.has_force and s.max_force_n is not None else math.inf
        self._max_angle = s.max_angle_deg if s.max_angle_deg is not None else math.inf
        self._over_torque = 0
        self._over_force = 0
        self._over_angle = 0

    @property
    def max_torque_nm(self) -> float:
        """The torque limit (inf without one): a halt plan never aims at or past it."""
        return self._max_torque

    def check(self, torque_nm: float, force_n: float | None, turned_deg: float) -> Stop | None:
        """One sample; ``force_n`` None when it has no force."""
        need = self._need
        self._over_torque = self._over_torque + 1 if torque_nm >= self._max_torque else 0
        if self._over_torque >= need:
            return Stop("torque_limit", f"torque ≥ {self._max_torque:g} Nm")
        over_force = force_n is not None and force_n >= self._max_force
        self._over_force = self._over_force + 1 if over_force else 0
        if self._over_force >= need:
            return Stop("force_limit", f"force ≥ {self._max_force:g} N")
        self._over_angle = self._over_angle + 1 if turned_deg >= self._max_angle else 0
        if self._over_angle >= need:
            return Stop("angle_limit", f"angle turned ≥ {self._max_angle:g}°")
        return None
