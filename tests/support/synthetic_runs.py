"""Synthetic traces for the predictor tests: the paper's lumped model, instant slips.

Stick (eq. 9): the screw stands, T = k_e (φ_m - φ_b) rises with the motor.
When T reaches F · r · μ_stick the screw slips at once to where
k_e (φ_m - φ_b) = F · r · μ_slip with F = F_0 + k_s φ_b (eqs. 10, 15). This
gives the clean sawtooth torque and staircase force of the paper's Fig. 10.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

FloatArray = npt.NDArray[np.floating[Any]]


@dataclass(frozen=True)
class SyntheticTrace:
    time_s: FloatArray
    torque_nm: FloatArray
    force_n: FloatArray
    angle_deg: FloatArray
    plateaus_n: list[float]  # every plateau the joint sat on, in order

    def rows(self) -> list[tuple[float, float, float, float]]:
        """(time_s, torque_nm, force_n, angle_deg): the order of PredictorCore.update."""
        return list(
            zip(
                self.time_s.tolist(),
                self.torque_nm.tolist(),
                self.force_n.tolist(),
                self.angle_deg.tolist(),
                strict=True,
            )
        )

    def csv_rows(self) -> list[tuple[float, float, float, float | None]]:
        """(time_s, torque_nm, angle_deg, force_n): the order of ``write_trace`` (the contract)."""
        return [(t, tq, a, f) for t, tq, f, a in self.rows()]


def staircase(
    *,
    k_e: float = 600.0,
    k_s: float = 80_000.0,
    r: float = 0.01,
    mu_stick: float = 0.36,
    mu_slip: float = 0.33,
    speed_rad_s: float = 0.5,
    start_force_n: float = 10_000.0,
    duration_s: float = 1.0,
    dt_s: float = 1e-3,
    torque_noise_nm: float = 0.0,
    force_noise_n: float = 0.0,
    seed: int = 0,
) -> SyntheticTrace:
    """A stick-slip run sampled every ``dt_s``."""
    rng = np.random.default_rng(seed)
    n = round(duration_s / dt_s)
    time_s = np.arange(n, dtype=np.float64) * dt_s
    torque = np.empty(n)
    force = np.empty(n)
    phi_b = start_force_n * r * mu_slip / k_e * 0.0
    plateaus = [start_force_n]
    for i, t in enumerate(time_s):
        phi_m = speed_rad_s * t + start_force_n * r * mu_slip / k_e
        f = start_force_n + k_s * phi_b
        tq = k_e * (phi_m - phi_b)
        if tq >= f * r * mu_stick:
            phi_b = (k_e * phi_m - start_force_n * r * mu_slip) / (k_e + k_s * r * mu_slip)
            f = start_force_n + k_s * phi_b
            tq = k_e * (phi_m - phi_b)
            plateaus.append(f)
        torque[i] = tq
        force[i] = f
    angle = np.degrees(speed_rad_s * time_s)
    torque += rng.normal(0.0, torque_noise_nm, n) if torque_noise_nm else 0.0
    force += rng.normal(0.0, force_noise_n, n) if force_noise_n else 0.0
    return SyntheticTrace(time_s, torque, force, angle, plateaus)


def smooth_ramp(
    *, duration_s: float = 1.0, dt_s: float = 1e-3, force_rate_n_s: float = 50_000.0
) -> SyntheticTrace:
    """A joint without stick-slip: torque and force rise smoothly together."""
    n = round(duration_s / dt_s)
    time_s = np.arange(n, dtype=np.float64) * dt_s
    force = 10_000.0 + force_rate_n_s * time_s
    torque = force * 0.0036
    return SyntheticTrace(time_s, torque, force, np.degrees(0.5 * time_s), [])
