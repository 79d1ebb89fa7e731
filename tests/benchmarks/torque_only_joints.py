"""The joints of the torque-only benchmark: families drawn wider than the paper's ranges.

A family is a name, a role and a seed. The drawn families take each joint's
shape from what a station sees, not from the lumped constants:

- the slip drop ΔT, 2-25 % of the target torque (log-uniform). μ_slip is
  solved for it: a slip starts at T = μ_stick,j · F · r and, the motor
  standing still during the short slip, the screw swings past the rest point
  K φ_b = k_e φ_m (K = k_e + μ_slip k_s r, eq. 14) by the overshoot of the
  damped oscillator (:mod:`services.rig.slip_oscillator`), so

      ΔT / T_peak = (1 + e^(−ζπ/√(1−ζ²))) · (1 − μ_slip/μ_stick) · k_e / K

  which falls as μ_slip rises: bisection;
- the scatter of μ_stick from stick phase to stick phase, 0-5 % (uniform);
- the stick ramp, 1-20 samples per percent of the target torque
  (log-uniform): the motor speed w = 0.01 T* / (k_e · n · 1 ms);
- sensor noise: torque 0.02-0.3 % of the target torque, force 0.02-0.2 %
  of the target force (uniform);
- the rest across the paper's ranges (k_e 200-2000 Nm/rad, k_s 30-180
  kN/rad, r 8-14 mm, μ_stick 0.1-0.4, targets 30-60 kN from a quarter of
  the target).

The "paper" family is the two joints of ``config/joints`` (Sections 3.4 and
5.2) with the station's two programs (56 kN at 0.5 rad/s, 40 kN at 1 rad/s),
scatter and noise drawn as above.

The torque target of every joint is T* = F* · r · μ_stick, the peak torque of
the stick phase that ends at the target preload.
"""

from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from shared.config import JointConfig, Program, RigSection
from shared.model import JointConstants
from tests.support.model_band_runs import drawn_program

REPO = Path(__file__).resolve().parents[2]
SAMPLE_S = 1e-3
START_SHARE = 0.25  # a run starts at this share of the target preload
RAMPS_SAMPLES_PER_PCT = (1.0, 20.0)  # the drawn families' stick ramps, samples per % of T*

#: name -> (role, seed). Rules are tuned on the "tune" families only and judged on the rest.
FAMILIES: dict[str, tuple[str, int]] = {
    "tune-a": ("tune", 101),
    "tune-b": ("tune", 102),
    "judge-a": ("judge", 201),
    "judge-b": ("judge", 202),
    "judge-c": ("judge", 203),
    "paper": ("judge", 301),
}
PAPER_JOINTS = ("paper-section-5-2.toml", "paper-section-3-4.toml")
PAPER_PROGRAMS = ((56_000.0, 0.5), (40_000.0, 1.0))  # (target N, motor rad/s)


@dataclass(frozen=True)
class Joint:
    """One joint of a family, and what it was drawn as."""

    family: str
    number: int
    constants: JointConstants
    program: Program
    rig: RigSection
    target_force_n: float
    target_torque_nm: float
    seed: int
    drop_share: float  # nominal ΔT / T* drawn
    ramp_samples_per_pct: float  # stick ramp: samples per percent of T*


def overshoot(damping_ratio: float) -> float:
    """The damped oscillator's swing past its rest point, as a share of the way to it."""
    return math.exp(-damping_ratio * math.pi / math.sqrt(1.0 - damping_ratio**2))


def drop_share(
    k_e: float, k_s: float, r: float, mu_stick: float, mu_slip: float, zeta: float
) -> float:
    """ΔT / T_peak of a slip (module docstring)."""
    stiffness = k_e + mu_slip * k_s * r
    return (1.0 + overshoot(zeta)) * (1.0 - mu_slip / mu_stick) * k_e / stiffness


def mu_slip_for_drop(
    k_e: float, k_s: float, r: float, mu_stick: float, share: float, zeta: float
) -> float:
    """μ_slip whose slip drops ``share`` of the peak torque (bisection; drop falls with μ_slip)."""
    low, high = 1e-6 * mu_stick, mu_stick * (1.0 - 1e-6)
    for _ in range(100):
        middle = 0.5 * (low + high)
        if drop_share(k_e, k_s, r, mu_stick, middle, zeta) > share:
            low = middle
        else:
            high = middle
    return 0.5 * (low + high)


def _program(constants: JointConstants, target_n: float, speed: float) -> Program:
    c = constants
    # time to the target: twist of the extension plus turning of the screw (eqs. 27-29)
    start = START_SHARE * target_n
    expected_s = (
        target_n * c.r_m * c.mu_stick / c.k_e_nm_per_rad + (target_n - start) / (c.k_s_n_per_rad)
    ) / speed
    return drawn_program(speed, target_n, 3.0 * expected_s + 1.0)


def _noise(
    rng: np.random.Generator, target_nm: float, target_n: float, scatter: float
) -> RigSection:
    return RigSection(
        mu_stick_scatter=scatter,
        torque_noise_nm=target_nm * rng.uniform(0.0002, 0.003),
        force_noise_n=target_n * rng.uniform(0.0002, 0.002),
    )


def drawn_joint(
    family: str,
    number: int,
    rng: np.random.Generator,
    seed: int,
    ramps_samples_per_pct: tuple[float, float] = RAMPS_SAMPLES_PER_PCT,
) -> Joint:
    """One joint of a drawn family (module docstring); its stick ramp log-uniform within
    ``ramps_samples_per_pct`` (samples per percent of the target torque)."""
    k_e = rng.uniform(200.0, 2000.0)
    k_s = rng.uniform(30_000.0, 180_000.0)
    r = rng.uniform(0.008, 0.014)
    mu_stick = rng.uniform(0.1, 0.4)
    share = math.exp(rng.uniform(math.log(0.02), math.log(0.25)))
    scatter = rng.uniform(0.0, 0.05)
    fast, slow = ramps_samples_per_pct
    ramp = math.exp(rng.uniform(math.log(fast), math.log(slow)))
    target_n = rng.uniform(30_000.0, 60_000.0)
    rig = _noise(rng, target_n * r * mu_stick, target_n, scatter)
    mu_slip = mu_slip_for_drop(k_e, k_s, r, mu_stick, share, rig.damping_ratio)
    constants = JointConstants(k_e, k_s, r, mu_stick, mu_slip)
    target_nm = target_n * r * mu_stick
    speed = 0.01 * target_nm / (k_e * ramp * SAMPLE_S)
    program = _program(constants, target_n, speed)
    return Joint(family, number, constants, program, rig, target_n, target_nm, seed, share, ramp)


def paper_joint(number: int, rng: np.random.Generator, seed: int) -> Joint:
    """One run of the paper's joints and programs, with drawn scatter and noise."""
    name = PAPER_JOINTS[number % len(PAPER_JOINTS)]
    target_n, speed = PAPER_PROGRAMS[(number // len(PAPER_JOINTS)) % len(PAPER_PROGRAMS)]
    text = (REPO / "config" / "joints" / name).read_text(encoding="utf-8")
    constants = JointConstants.of(JointConfig.model_validate(tomllib.loads(text)))
    c = constants
    target_nm = target_n * c.r_m * c.mu_stick
    rig = _noise(rng, target_nm, target_n, rng.uniform(0.0, 0.05))
    share = drop_share(
        c.k_e_nm_per_rad, c.k_s_n_per_rad, c.r_m, c.mu_stick, c.mu_slip, rig.damping_ratio
    )
    ramp = 0.01 * target_nm / (c.k_e_nm_per_rad * speed * SAMPLE_S)
    program = _program(constants, target_n, speed)
    return Joint("paper", number, constants, program, rig, target_n, target_nm, seed, share, ramp)


def family_joints(family: str, count: int) -> list[Joint]:
    """The first ``count`` joints of a family; the same ones on every call."""
    if family not in FAMILIES:
        raise ValueError(f"unknown family {family!r}: expected one of {', '.join(FAMILIES)}")
    _, family_seed = FAMILIES[family]
    rng = np.random.default_rng(family_seed)
    joints = []
    for number in range(count):
        seed = family_seed * 10_000 + number
        if family == "paper":
            joints.append(paper_joint(number, rng, seed))
        else:
            joints.append(drawn_joint(family, number, rng, seed))
    return joints
