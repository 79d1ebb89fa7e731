"""The characteristic constants K1-K3 and their expected bands (paper Section 3.3, eqs. 31-39).

Measured per stick-slip event (Figure 3 metrics; t is model time, see
:mod:`shared.model.timing`):

    K1 ≈ f_ss · t                 dimensionless                       (31)
    K2 ≈ ΔF / Δt · φ̇_m            N·rad/s²                            (32)
    K3 ≈ ΔT / t · φ̇_m             Nm·rad/s²                           (33)

Bands. With φ_m = φ̇_m t every bound of eqs. 18-26 is proportional to t
(angles, ΔT, ΔF) or to 1/t (f_ss), so each band below is a constant of the
joint and the motor speed; we evaluate every factor at the same model time t
and t cancels:

    K1_min = f_ss,min · t = 1 / (1 − γ_stick)                         (34, from 25)
    K1_max = f_ss,max · t = 1 / (γ_slip − γ_stick)                    (35, from 26)
    K3_min = Δφ_b · k_e / t · φ̇_m = k_e φ̇_m² (γ_slip − γ_stick)       (38)
    K3_max = φ_0,stick · k_e / t · φ̇_m = k_e φ̇_m² (1 − γ_stick)      (39)

K2 (eqs. 36, 37) multiplies a force step by a frequency. Pairing each step
with the frequency of the same slip, as eqs. 25-26 are derived (Δφ_b with
f_ss,max, φ_0,stick with f_ss,min), gives k_s · φ̇_m² for *both* bounds: in
the paper's model ΔF / Δt is the screw's mean force rate, whatever the slip.
To give a band, we read eqs. 36-37 as interval products of independent
bounds at the same t, the smallest step with the lowest frequency and the
largest with the highest:

    K2_min = ΔF_min · f_ss,min · φ̇_m = k_s φ̇_m² (γ_slip − γ_stick) / (1 − γ_stick)   (36)
    K2_max = ΔF_max · f_ss,max · φ̇_m = k_s φ̇_m² (1 − γ_stick) / (γ_slip − γ_stick)   (37)

The exact lumped model (slips start on φ_b = γ_stick φ_m, eq. 16, so
successive plateaus lie on F = k_s γ_stick φ̇_m t) has K2 = γ_stick k_s φ̇_m²,
inside this band: :func:`stick_line_k2`. With partial relief ρ (Section 5.3)
slips shrink by ρ and periods with them: K1 bounds scale by 1/ρ, K3 by ρ, K2
not at all.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

from shared.model.angles import Value, angle_ratio
from shared.model.slip_bounds import FULL_RELIEF
from shared.model.stiffness import JointConstants


def k1_of(stick_slip_frequency_hz: Value, time_s: Value) -> Value:
    """K1 = f_ss · t (eq. 31)."""
    return stick_slip_frequency_hz * time_s


def k2_of(force_step_n: Value, step_duration_s: Value, motor_speed_rad_s: float) -> Value:
    """K2 = ΔF / Δt · φ̇_m, N·rad/s² (eq. 32)."""
    return force_step_n / step_duration_s * motor_speed_rad_s


def k3_of(torque_drop_nm: Value, time_s: Value, motor_speed_rad_s: float) -> Value:
    """K3 = ΔT / t · φ̇_m, Nm·rad/s² (eq. 33); t is model time."""
    return torque_drop_nm / time_s * motor_speed_rad_s


@dataclass(frozen=True, slots=True)
class ConstantBands:
    """Expected bands of K1 (-), K2 (N·rad/s²) and K3 (Nm·rad/s²) of one joint and speed."""

    k1_min: float
    k1_max: float
    k2_min: float
    k2_max: float
    k3_min: float
    k3_max: float

    def as_dict(self) -> dict[str, float]:
        return asdict(self)


def expected_constant_bands(
    constants: JointConstants, motor_speed_rad_s: float, relief_fraction: float = FULL_RELIEF
) -> ConstantBands:
    """The K1-K3 bands of eqs. 34-39 for a configured joint, known before the first event.

    ``relief_fraction`` ρ in (0, 1]: 1 is the paper's solid lines, 0.5 its dashed ones.
    """
    if not 0.0 < relief_fraction <= 1.0:
        raise ValueError(f"relief_fraction must be in (0, 1] (got {relief_fraction})")
    if motor_speed_rad_s <= 0.0:
        raise ValueError(f"motor_speed_rad_s must be positive (got {motor_speed_rad_s})")
    k_e, k_s, r = constants.k_e_nm_per_rad, constants.k_s_n_per_rad, constants.r_m
    gamma_stick = angle_ratio(k_e, k_s, r, constants.mu_stick)
    gamma_slip = angle_ratio(k_e, k_s, r, constants.mu_slip)
    slip_share = gamma_slip - gamma_stick  # Δφ_b / φ_m, eq. 18
    twist_share = 1.0 - gamma_stick  # φ_0,stick / φ_m, eq. 19
    speed_sq = motor_speed_rad_s**2
    rho = relief_fraction
    return ConstantBands(
        k1_min=1.0 / (twist_share * rho),
        k1_max=1.0 / (slip_share * rho),
        k2_min=k_s * speed_sq * slip_share / twist_share,
        k2_max=k_s * speed_sq * twist_share / slip_share,
        k3_min=k_e * speed_sq * slip_share * rho,
        k3_max=k_e * speed_sq * twist_share * rho,
    )


def stick_line_k2(constants: JointConstants, motor_speed_rad_s: float) -> float:
    """K2 = γ_stick · k_s · φ̇_m², N·rad/s²: the exact lumped model's value (module docstring)."""
    gamma_stick = angle_ratio(
        constants.k_e_nm_per_rad, constants.k_s_n_per_rad, constants.r_m, constants.mu_stick
    )
    return gamma_stick * constants.k_s_n_per_rad * motor_speed_rad_s**2
