"""The paper's analytical model (Baramsky et al. 2018, Sections 3-4), pure numpy.

Angles in radians, stiffnesses per radian: see :mod:`shared.model.stiffness`.
"""

from shared.model.stiffness import (
    JointConstants,
    extension_stiffness_nm_per_rad,
    friction_radius_m,
    screw_stiffness_n_per_rad,
)

__all__ = [
    "JointConstants",
    "extension_stiffness_nm_per_rad",
    "friction_radius_m",
    "screw_stiffness_n_per_rad",
]
