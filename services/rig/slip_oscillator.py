"""The sliding screw as a damped linear oscillator, solved in closed form.

During a slip (paper Section 3.1, "Sliding phase") the screw turns forward,
φ̇_b > 0, against Coulomb friction at the surrogate radius r (eq. 10) and is
driven through the extension of stiffness k_e (eq. 2) by the motor angle φ_m:

    J φ̈_b = k_e (φ_m − φ_b) − μ_slip · F · r − c φ̇_b              (eq. 10 with inertia)

With the preload F = k_s · φ_b (eq. 8) the friction torque is linear in φ_b, so

    J φ̈_b + c φ̇_b + K φ_b = k_e φ_m(t),     K = k_e + μ_slip · k_s · r     (cf. eq. 14)

a linear oscillator with constant coefficients (K does not depend on F). Its
static solution K φ_b = k_e φ_m is the paper's φ_b,max = γ_slip · φ_m (eq. 17).
The damping c is a fraction ζ of critical, c = 2 ζ √(K J), acting on the
screw's own speed (viscous losses in the contact).

The motor turns at constant speed w (or stands, w = 0): φ_m(s) = φ_m0 + w s.
For such a ramp the particular solution is a ramp too, φ_p(s) = a + b s with

    K b = k_e w                      ->  b = k_e w / K
    K a + c b = k_e φ_m0             ->  a = (k_e φ_m0 − c b) / K

and the rest x = φ_b − φ_p obeys J ẍ + c ẋ + K x = 0, underdamped (ζ < 1):

    x(s)  = e^{−σs} [ x0 cos ω_d s + (ẋ0 + σ x0)/ω_d · sin ω_d s ]
    ẋ(s)  = e^{−σs} [ ẋ0 cos ω_d s − (σ ẋ0 + ω_n² x0)/ω_d · sin ω_d s ]

with ω_n² = K/J, σ = ζ ω_n, ω_d = ω_n √(1 − ζ²). So any instant of a slip is
evaluated exactly, whatever the step: no integration error accumulates.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from shared.model import JointConstants


@dataclass(frozen=True, slots=True)
class SlipOscillator:
    """Closed-form motion of the sliding screw (angles in rad, speeds in rad/s)."""

    k_e_nm_per_rad: float
    stiffness_nm_per_rad: float  # K = k_e + μ_slip k_s r
    damping_nm_s_per_rad: float  # c
    inertia_kg_m2: float  # J
    decay_per_s: float  # σ
    damped_rad_s: float  # ω_d
    natural_sq_per_s2: float  # ω_n²

    @classmethod
    def of(
        cls, constants: JointConstants, inertia_kg_m2: float, damping_ratio: float
    ) -> SlipOscillator:
        """The slip oscillator of a joint driven through its extension."""
        if not 0.0 <= damping_ratio < 1.0:
            raise ValueError(f"damping_ratio must be in [0, 1) (got {damping_ratio})")
        stiffness = constants.k_e_nm_per_rad + (
            constants.mu_slip * constants.k_s_n_per_rad * constants.r_m
        )
        natural = math.sqrt(stiffness / inertia_kg_m2)
        return cls(
            k_e_nm_per_rad=constants.k_e_nm_per_rad,
            stiffness_nm_per_rad=stiffness,
            damping_nm_s_per_rad=2.0 * damping_ratio * math.sqrt(stiffness * inertia_kg_m2),
            inertia_kg_m2=inertia_kg_m2,
            decay_per_s=damping_ratio * natural,
            damped_rad_s=natural * math.sqrt(1.0 - damping_ratio**2),
            natural_sq_per_s2=natural**2,
        )

    @property
    def half_period_s(self) -> float:
        """π / ω_d: about how long one undisturbed slip lasts."""
        return math.pi / self.damped_rad_s

    def state_after(
        self,
        angle_rad: float,
        speed_rad_s: float,
        motor_angle_rad: float,
        motor_speed_rad_s: float,
        elapsed_s: float,
    ) -> tuple[float, float]:
        """Screw angle and speed ``elapsed_s`` after the given state (still sliding)."""
        b = self.k_e_nm_per_rad * motor_speed_rad_s / self.stiffness_nm_per_rad
        a = (
            self.k_e_nm_per_rad * motor_angle_rad - self.damping_nm_s_per_rad * b
        ) / self.stiffness_nm_per_rad
        x0 = angle_rad - a
        dx0 = speed_rad_s - b
        sigma = self.decay_per_s
        omega_d = self.damped_rad_s
        decay = math.exp(-sigma * elapsed_s)
        cos_term = math.cos(omega_d * elapsed_s)
        sin_term = math.sin(omega_d * elapsed_s)
        x = decay * (x0 * cos_term + (dx0 + sigma * x0) / omega_d * sin_term)
        dx = decay * (
            dx0 * cos_term - (sigma * dx0 + self.natural_sq_per_s2 * x0) / omega_d * sin_term
        )
        return a + b * elapsed_s + x, b + dx
