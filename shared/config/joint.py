"""The joint file: geometry, material and friction of one bolted joint.

Values are the paper's parameters (Baramsky et al. 2018, Sections 3.4 and
5.2) in engineering units named in each key (mm, GPa). The analytical model
(:mod:`shared.model`) converts them to SI; nothing else should.

Example (``config/joints/paper-section-5-2.toml``)::

    name = "M14x1.5 10.9, paper Section 5.2"
    [material]
    shear_modulus_gpa = 81.0
    ...
"""

from __future__ import annotations

from pathlib import Path

from pydantic import Field, model_validator

from shared.config.loading import StrictModel, read_toml, validate


class Material(StrictModel):
    """Steel of screw and extension."""

    shear_modulus_gpa: float = Field(gt=0, description="G, eq. 2 and 40")
    youngs_modulus_gpa: float = Field(gt=0, description="E, eq. 5 and 8")
    density_kg_m3: float = Field(gt=0, description="ρ, eq. 40")


class Screw(StrictModel):
    """The screw: thread pitch, shaft and bearing surface."""

    pitch_mm: float = Field(gt=0, description="P, advance per revolution")
    shaft_diameter_mm: float = Field(gt=0, description="d, eq. 6 and 8")
    shaft_length_mm: float = Field(gt=0, description="l_s, effective (clamped) length")
    pitch_diameter_mm: float = Field(gt=0, description="d_2, eq. 30 and 41")
    bearing_outer_diameter_mm: float = Field(gt=0, description="d_o = 2 r_b,max, eq. 3")
    bearing_inner_diameter_mm: float = Field(gt=0, description="d_i = 2 r_b,min, eq. 3")

    @model_validator(mode="after")
    def _bearing_is_an_annulus(self) -> Screw:
        if self.bearing_inner_diameter_mm >= self.bearing_outer_diameter_mm:
            raise ValueError(
                "bearing_inner_diameter_mm must be smaller than bearing_outer_diameter_mm"
            )
        return self


class Extension(StrictModel):
    """The extension (drive train) between motor and socket."""

    length_mm: float = Field(gt=0, description="l_e, eq. 2 and 40")
    diameter_mm: float = Field(gt=0, description="d_e, eq. 2")


class Friction(StrictModel):
    """Coulomb friction of the (single, lumped) contact, eqs. 9 and 10."""

    mu_stick: float = Field(gt=0, lt=1.5)
    mu_slip: float = Field(gt=0, lt=1.5)
    mu_thread: float | None = Field(default=None, gt=0, lt=1.5, description="μ_th, eq. 30")
    mu_bearing: float | None = Field(default=None, gt=0, lt=1.5, description="μ_b, eq. 30")

    @model_validator(mode="after")
    def _slip_below_stick(self) -> Friction:
        if self.mu_slip > self.mu_stick:
            raise ValueError("mu_slip must not exceed mu_stick (stick-slip needs μ_stick ≥ μ_slip)")
        return self


class JointConfig(StrictModel):
    """One joint: what the rig simulates and what the model's bounds are computed for."""

    name: str
    material: Material
    screw: Screw
    extension: Extension
    friction: Friction


def load_joint(path: Path) -> JointConfig:
    """Load and validate a joint file; errors name the file and the key."""
    return validate(JointConfig, read_toml(path), path)
