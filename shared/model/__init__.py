"""The paper's analytical model (Baramsky et al. 2018, Sections 3-4), pure numpy.

Angles in radians, stiffnesses per radian: see :mod:`shared.model.stiffness`.
Model time t starts at the untwisted, unloaded joint (φ_m = φ̇_m · t); see
:mod:`shared.model.timing`. The modules, in the order of the paper:

    stiffness                 k_e, r, k_s                             eqs. 2, 3, 8
    angles                    γ_stick, γ_slip, φ_b bounds, Δφ_b, φ_0   eqs. 11-20
    slip_bounds               ΔT, ΔF, f_ss bounds, partial relief      eqs. 21-26
    timing                    t_e, t_screw, t_total, t(F), t(T)        eqs. 27-29
    torque_preload            T <-> F, μ_total, μ*                     eqs. 30, 41, 42
    characteristic_constants  K1-K3 and their bands                    eqs. 31-39
    resonance                 natural frequency of the extension       eq. 40
    joint_model               all of it for one joint and speed, over t

and around it: ``envelope_check`` (measured events against the envelopes, Figs.
13-15), ``report`` (what ``boltwatch model`` prints), ``figures`` (its plot).
"""

from shared.model.characteristic_constants import (
    ConstantBands,
    expected_constant_bands,
    stick_line_k2,
)
from shared.model.joint_model import JointModel
from shared.model.stiffness import (
    JointConstants,
    extension_stiffness_nm_per_rad,
    friction_radius_m,
    screw_stiffness_n_per_rad,
)

__all__ = [
    "ConstantBands",
    "JointConstants",
    "JointModel",
    "expected_constant_bands",
    "extension_stiffness_nm_per_rad",
    "friction_radius_m",
    "screw_stiffness_n_per_rad",
    "stick_line_k2",
]
