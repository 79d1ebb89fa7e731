"""The analytical report of one configured joint (what ``boltwatch model`` prints).

:func:`joint_report` evaluates the model of :mod:`shared.model` for a joint
file, a motor speed and the targets, and returns a nested dict of plain
floats (JSON-ready, units in the keys); :func:`format_report` renders it for
people. "At the target" means at the model time of the target preload (else
of the target torque), see :meth:`JointModel.time_at_force_s`.
"""

from __future__ import annotations

from typing import Any

from shared.config import JointConfig
from shared.errors import InputError
from shared.model import torque_preload
from shared.model.characteristic_constants import stick_line_k2
from shared.model.joint_model import JointModel
from shared.model.resonance import extension_natural_frequency_hz
from shared.model.slip_bounds import PAPER_PARTIAL_RELIEF
from shared.model.stiffness import GPA, MM, JointConstants

#: the extension's natural frequency counts as "near" the stick-slip band below this factor
NEAR_FACTOR = 2.0


def joint_report(
    joint: JointConfig,
    motor_speed_rad_s: float,
    target_force_n: float | None,
    target_torque_nm: float | None,
) -> dict[str, Any]:
    """Every number of the report, in SI units named in the keys."""
    if motor_speed_rad_s <= 0.0:
        raise InputError(f"--speed must be positive (got {motor_speed_rad_s} rad/s)")
    if target_force_n is None and target_torque_nm is None:
        raise InputError("give --target-force, --target-torque, or both")
    for name, value in (("--target-force", target_force_n), ("--target-torque", target_torque_nm)):
        if value is not None and value <= 0.0:
            raise InputError(f"{name} must be positive (got {value})")
    constants = JointConstants.of(joint)
    model = JointModel(constants, motor_speed_rad_s)
    partial = model.with_relief(PAPER_PARTIAL_RELIEF)
    if target_force_n is not None:
        t_target = float(model.time_at_force_s(target_force_n))
        basis = "target force"
    else:
        assert target_torque_nm is not None
        t_target = float(model.time_at_torque_s(target_torque_nm))
        basis = "target torque"
    report: dict[str, Any] = {
        "joint": joint.name,
        "motor_speed_rad_s": motor_speed_rad_s,
        "target_force_n": target_force_n,
        "target_torque_nm": target_torque_nm,
        "constants": {
            "k_e_nm_per_rad": constants.k_e_nm_per_rad,
            "k_s_n_per_rad": constants.k_s_n_per_rad,
            "r_m": constants.r_m,
            "mu_stick": constants.mu_stick,
            "mu_slip": constants.mu_slip,
            "gamma_stick": model.gamma_stick,
            "gamma_slip": model.gamma_slip,
        },
        "time": _time_section(model, target_force_n, target_torque_nm, t_target, basis),
        "at_target": _at_target(model, partial, t_target),
        "constant_bands": model.constant_bands().as_dict(),
        "constant_bands_partial_relief": partial.constant_bands().as_dict(),
        "k2_stick_line": stick_line_k2(constants, motor_speed_rad_s),
        "torque_preload": _torque_preload(joint, constants, target_force_n, target_torque_nm),
    }
    f_n = extension_natural_frequency_hz(
        joint.material.shear_modulus_gpa * GPA,
        joint.material.density_kg_m3,
        joint.extension.length_mm * MM,
    )
    f_max = report["at_target"]["stick_slip_frequency_max_hz"]
    report["resonance"] = {
        "extension_natural_frequency_hz": f_n,
        "ratio_to_stick_slip_max": f_n / f_max,
        "near_stick_slip_band": bool(f_n <= NEAR_FACTOR * f_max),
    }
    return report


def _time_section(
    model: JointModel,
    target_force_n: float | None,
    target_torque_nm: float | None,
    t_target: float,
    basis: str,
) -> dict[str, Any]:
    section: dict[str, Any] = {"model_time_at_target_s": t_target, "basis": basis}
    if target_force_n is not None:
        section["time_at_target_force_s"] = float(model.time_at_force_s(target_force_n))
        section["peak_torque_at_target_force_nm"] = float(model.peak_torque_nm(t_target))
    if target_torque_nm is not None:
        section["time_at_target_torque_s"] = float(model.time_at_torque_s(target_torque_nm))
    if target_force_n is not None and target_torque_nm is not None:
        section["total_time_eq27_s"] = model.total_time_s(target_torque_nm, target_force_n)
    return section


def _at_target(model: JointModel, partial: JointModel, t_s: float) -> dict[str, float]:
    return {
        "motor_angle_rad": float(model.motor_angle_rad(t_s)),
        "slip_angle_rad": float(model.slip_angle_rad(t_s)),
        "stick_slip_frequency_min_hz": float(model.stick_slip_frequency_min_hz(t_s)),
        "stick_slip_frequency_max_hz": float(model.stick_slip_frequency_max_hz(t_s)),
        "stick_slip_frequency_partial_min_hz": float(partial.stick_slip_frequency_min_hz(t_s)),
        "stick_slip_frequency_partial_max_hz": float(partial.stick_slip_frequency_max_hz(t_s)),
        "force_step_min_n": float(model.force_step_min_n(t_s)),
        "force_step_max_n": float(model.force_step_max_n(t_s)),
        "torque_drop_min_nm": float(model.torque_drop_min_nm(t_s)),
        "torque_drop_max_nm": float(model.torque_drop_max_nm(t_s)),
    }


def _torque_preload(
    joint: JointConfig,
    constants: JointConstants,
    target_force_n: float | None,
    target_torque_nm: float | None,
) -> dict[str, float]:
    screw, friction = joint.screw, joint.friction
    pitch_m, d2_m, r_m = screw.pitch_mm * MM, screw.pitch_diameter_mm * MM, constants.r_m
    section: dict[str, float] = {}
    if friction.mu_thread is not None and friction.mu_bearing is not None:
        mus = (friction.mu_thread, friction.mu_bearing)
        if target_force_n is not None:
            section["torque_for_target_force_nm"] = torque_preload.torque_for_force_nm(
                target_force_n, pitch_m, d2_m, r_m, *mus
            )
        if target_torque_nm is not None:
            section["force_for_target_torque_n"] = torque_preload.force_for_torque_n(
                target_torque_nm, pitch_m, d2_m, r_m, *mus
            )
    if target_force_n is not None and target_torque_nm is not None:
        section["mu_total"] = torque_preload.total_friction_coefficient(
            target_torque_nm, target_force_n, pitch_m, d2_m, r_m
        )
        section["mu_apparent"] = torque_preload.apparent_friction_coefficient(
            target_torque_nm, target_force_n, r_m
        )
    return section


def format_report(report: dict[str, Any]) -> str:
    """The report as aligned text lines."""
    c, tm, at = report["constants"], report["time"], report["at_target"]
    bands, partial = report["constant_bands"], report["constant_bands_partial_relief"]
    targets = []
    if report["target_force_n"] is not None:
        targets.append(f"F = {report['target_force_n'] / 1e3:.1f} kN")
    if report["target_torque_nm"] is not None:
        targets.append(f"T = {report['target_torque_nm']:.1f} Nm")
    lines = [
        f"joint           {report['joint']}",
        f"motor speed     {report['motor_speed_rad_s']:.3g} rad/s    targets: {', '.join(targets)}",
        "",
        "stiffness (per radian, eqs. 2, 3, 8)",
        f"  k_e = {c['k_e_nm_per_rad']:.1f} Nm/rad   k_s = {c['k_s_n_per_rad'] / 1e3:.1f} kN/rad"
        f"   r = {c['r_m'] / MM:.2f} mm",
        f"  μ_stick = {c['mu_stick']:.3g}   μ_slip = {c['mu_slip']:.3g}"
        f"   γ_stick = {c['gamma_stick']:.4f}   γ_slip = {c['gamma_slip']:.4f}  (eqs. 16, 17)",
        "",
        "time (model time from the untwisted, unloaded joint; eqs. 27-29)",
    ]
    if "time_at_target_force_s" in tm:
        lines.append(
            f"  target force reached at t = {tm['time_at_target_force_s']:.3f} s"
            f"  (peak torque there {tm['peak_torque_at_target_force_nm']:.1f} Nm)"
        )
    if "time_at_target_torque_s" in tm:
        lines.append(f"  target torque reached at t = {tm['time_at_target_torque_s']:.3f} s")
    if "total_time_eq27_s" in tm:
        lines.append(f"  t_total = t_e + t_screw = {tm['total_time_eq27_s']:.3f} s (eq. 27)")
    lines += [
        "",
        f"at the target (t = {tm['model_time_at_target_s']:.3f} s, from the {tm['basis']})",
        f"  stick-slip frequency  {at['stick_slip_frequency_min_hz']:8.1f} .. "
        f"{at['stick_slip_frequency_max_hz']:8.1f} Hz   (eqs. 25, 26)",
        f"    50 % relief         {at['stick_slip_frequency_partial_min_hz']:8.1f} .. "
        f"{at['stick_slip_frequency_partial_max_hz']:8.1f} Hz",
        f"  force step            {at['force_step_min_n']:8.0f} .. "
        f"{at['force_step_max_n']:8.0f} N    (eqs. 23, 24)",
        f"  torque drop           {at['torque_drop_min_nm']:8.1f} .. "
        f"{at['torque_drop_max_nm']:8.1f} Nm   (eqs. 21, 22)",
        "",
        "characteristic constants (eqs. 34-39; time independent)",
        f"  K1  {bands['k1_min']:10.3g} .. {bands['k1_max']:10.3g}   -"
        f"            (50 % relief {partial['k1_min']:.3g} .. {partial['k1_max']:.3g})",
        f"  K2  {bands['k2_min']:10.3g} .. {bands['k2_max']:10.3g}   N·rad/s²"
        f"     (stick line γ_stick k_s φ̇²: {report['k2_stick_line']:.3g})",
        f"  K3  {bands['k3_min']:10.3g} .. {bands['k3_max']:10.3g}   Nm·rad/s²"
        f"    (50 % relief {partial['k3_min']:.3g} .. {partial['k3_max']:.3g})",
        "",
        "torque and preload (eqs. 30, 41, 42)",
    ]
    lines += _format_torque_preload(report["torque_preload"])
    res = report["resonance"]
    verdict = "NEAR the stick-slip band" if res["near_stick_slip_band"] else "far above"
    lines += [
        "",
        "resonance of the extension (eq. 40)",
        f"  f_n = {res['extension_natural_frequency_hz']:.0f} Hz:"
        f" {res['ratio_to_stick_slip_max']:.1f} x f_ss,max at the target, {verdict}",
    ]
    return "\n".join(lines)


def _format_torque_preload(section: dict[str, float]) -> list[str]:
    lines = []
    if "torque_for_target_force_nm" in section:
        lines.append(f"  T for the target force = {section['torque_for_target_force_nm']:.1f} Nm")
    if "force_for_target_torque_n" in section:
        lines.append(
            f"  F for the target torque = {section['force_for_target_torque_n'] / 1e3:.2f} kN"
        )
    if "mu_total" in section:
        lines.append(
            f"  μ_total = {section['mu_total']:.3f} (eq. 41)   μ* = {section['mu_apparent']:.3f}"
            " (eq. 42)"
        )
    if not lines:
        lines.append("  (give mu_thread and mu_bearing in the joint file, or both targets)")
    return lines
