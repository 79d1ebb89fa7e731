"""The report's figure: the model's bounds over time and over the extension geometry.

One PNG with nine panels after the paper's figures: stick-slip frequency,
force step and torque drop bounds over model time with the 50 % relief
variant dashed (Figures 13-15); the torque and preload envelopes and the
screw angles (Figures 10, 11); the frequency bound over the tightening
progress for three motor speeds (Figure 4); γ_stick and γ_slip over the
extension's length and diameter (Figure 6); its natural frequency over length
(Figure 7). matplotlib (Agg) is imported inside :func:`draw_joint_figure`, so
the rest of :mod:`shared.model` stays pure numpy.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from shared.config import JointConfig
from shared.errors import naming
from shared.model.angles import angle_ratio
from shared.model.joint_model import JointModel
from shared.model.resonance import extension_natural_frequency_hz
from shared.model.slip_bounds import PAPER_PARTIAL_RELIEF
from shared.model.stiffness import GPA, MM, JointConstants, extension_stiffness_nm_per_rad

#: the paper's ranges of typical extensions (Section 3.4)
LENGTH_RANGE_MM = (50.0, 500.0)
DIAMETER_RANGE_MM = (8.0, 15.0)
SPEED_FACTORS = (0.5, 1.0, 4.0)
FULL_STYLE = {"color": "tab:blue"}
PARTIAL_STYLE = {"color": "tab:blue", "linestyle": "--", "alpha": 0.7}


def draw_joint_figure(
    joint: JointConfig, motor_speed_rad_s: float, target_time_s: float, path: Path
) -> None:
    """Write the nine-panel figure of ``joint`` at ``motor_speed_rad_s`` to ``path`` (PNG)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    constants = JointConstants.of(joint)
    model = JointModel(constants, motor_speed_rad_s)
    partial = model.with_relief(PAPER_PARTIAL_RELIEF)
    t_s = np.linspace(target_time_s * 0.02, target_time_s * 1.1, 300)

    fig, axes = plt.subplots(3, 3, figsize=(16, 13))
    fig.suptitle(
        f"{joint.name}: analytical bounds at φ̇_m = {motor_speed_rad_s:g} rad/s "
        f"(model time from the unloaded joint; target at t = {target_time_s:.2f} s)",
        fontsize=13,
    )
    _band(
        axes[0, 0],
        t_s,
        (model.stick_slip_frequency_min_hz(t_s), model.stick_slip_frequency_max_hz(t_s)),
        (partial.stick_slip_frequency_min_hz(t_s), partial.stick_slip_frequency_max_hz(t_s)),
        "stick-slip frequency f_ss (eqs. 25, 26)",
        "f_ss / Hz",
        log=True,
    )
    _band(
        axes[0, 1],
        t_s,
        (model.force_step_min_n(t_s) / 1e3, model.force_step_max_n(t_s) / 1e3),
        (partial.force_step_min_n(t_s) / 1e3, partial.force_step_max_n(t_s) / 1e3),
        "force step ΔF (eqs. 23, 24)",
        "ΔF / kN",
        log=True,
    )
    _band(
        axes[0, 2],
        t_s,
        (model.torque_drop_min_nm(t_s), model.torque_drop_max_nm(t_s)),
        (partial.torque_drop_min_nm(t_s), partial.torque_drop_max_nm(t_s)),
        "torque drop ΔT (eqs. 21, 22)",
        "ΔT / Nm",
        log=True,
    )
    for ax in axes[0]:
        ax.axvline(target_time_s, color="tab:red", linewidth=1, label="target")
        ax.legend(loc="lower right", fontsize=8)

    _envelopes(axes[1, 0], model, t_s, target_time_s)
    _angles(axes[1, 1], model, t_s)
    _progress(axes[1, 2], constants, motor_speed_rad_s, target_time_s)
    _geometry(axes[2, 0], axes[2, 1], joint, constants)
    _natural_frequency(axes[2, 2], joint, model, target_time_s)
    for ax in axes.flat:
        ax.grid(True, which="both", alpha=0.3)
    fig.tight_layout(rect=(0, 0, 1, 0.97))
    with naming(path):
        fig.savefig(path, dpi=90)
    plt.close(fig)


def _band(
    ax: Any,
    t_s: np.ndarray,
    full: tuple[Any, Any],
    partial: tuple[Any, Any],
    title: str,
    ylabel: str,
    *,
    log: bool = False,
) -> None:
    ax.fill_between(t_s, full[0], full[1], alpha=0.15, color="tab:blue")
    ax.plot(t_s, full[0], **FULL_STYLE, label="min / max")
    ax.plot(t_s, full[1], **FULL_STYLE)
    ax.plot(t_s, partial[0], **PARTIAL_STYLE, label="50 % relief")
    ax.plot(t_s, partial[1], **PARTIAL_STYLE)
    ax.set(title=title, xlabel="model time t / s", ylabel=ylabel)
    if log:
        ax.set_yscale("log")


def _envelopes(ax: Any, model: JointModel, t_s: np.ndarray, target_time_s: float) -> None:
    ax.plot(t_s, model.peak_torque_nm(t_s), color="tab:orange", label="peak torque T_stick")
    ax.plot(t_s, model.slip_torque_nm(t_s), color="tab:orange", linestyle=":", label="T_slip")
    ax.set(title="torque and preload envelopes (Fig. 10)", xlabel="model time t / s")
    ax.set_ylabel("T / Nm", color="tab:orange")
    right = ax.twinx()
    right.plot(t_s, model.force_at_stick_n(t_s) / 1e3, color="tab:green", label="F at stick")
    right.plot(
        t_s, model.force_at_slip_n(t_s) / 1e3, color="tab:green", linestyle=":", label="F at slip"
    )
    right.set_ylabel("F / kN", color="tab:green")
    ax.axvline(target_time_s, color="tab:red", linewidth=1)
    lines = [line for line in ax.get_lines() + right.get_lines() if line.get_label()[0] != "_"]
    ax.legend(lines, [line.get_label() for line in lines], loc="upper left", fontsize=8)


def _angles(ax: Any, model: JointModel, t_s: np.ndarray) -> None:
    ax.plot(t_s, model.motor_angle_rad(t_s), color="black", label="φ_m")
    ax.plot(t_s, model.bearing_angle_max_rad(t_s), color="tab:green", label="φ_b,max (eq. 17)")
    ax.plot(t_s, model.bearing_angle_min_rad(t_s), color="tab:purple", label="φ_b,min (eq. 16)")
    ax.plot(t_s, model.slip_angle_rad(t_s), color="tab:gray", label="Δφ_b (eq. 18)")
    ax.set(title="angles (Fig. 11)", xlabel="model time t / s", ylabel="angle / rad")
    ax.legend(loc="upper left", fontsize=8)


def _progress(
    ax: Any, constants: JointConstants, motor_speed_rad_s: float, target_time_s: float
) -> None:
    progress = np.linspace(0.05, 1.0, 200)
    for factor in SPEED_FACTORS:
        speed = motor_speed_rad_s * factor
        model = JointModel(constants, speed)
        t_end_s = target_time_s / factor  # φ_m at the target is the same for every speed
        (line,) = ax.plot(
            progress,
            model.stick_slip_frequency_max_hz(progress * t_end_s),
            label=f"f_ss,max at {speed:g} rad/s",
        )
        ax.plot(
            progress,
            model.stick_slip_frequency_min_hz(progress * t_end_s),
            color=line.get_color(),
            linestyle=":",
        )
    ax.set_yscale("log")
    ax.set(
        title="f_ss over tightening progress (Fig. 4; dotted: min)",
        xlabel="progress t / t_target",
        ylabel="f_ss / Hz",
    )
    ax.legend(loc="upper right", fontsize=8)


def _geometry(
    ax_length: Any, ax_diameter: Any, joint: JointConfig, constants: JointConstants
) -> None:
    shear_pa = joint.material.shear_modulus_gpa * GPA
    lengths_mm = np.linspace(*LENGTH_RANGE_MM, 120)
    diameters_mm = np.linspace(*DIAMETER_RANGE_MM, 120)
    d_e_m, l_e_m = joint.extension.diameter_mm * MM, joint.extension.length_mm * MM
    for ax, xs_mm, stiffness in (
        (
            ax_length,
            lengths_mm,
            [extension_stiffness_nm_per_rad(shear_pa, d_e_m, x * MM) for x in lengths_mm],
        ),
        (
            ax_diameter,
            diameters_mm,
            [extension_stiffness_nm_per_rad(shear_pa, x * MM, l_e_m) for x in diameters_mm],
        ),
    ):
        k_e = np.asarray(stiffness, dtype=np.float64)
        ratio = constants.k_s_n_per_rad * constants.r_m
        ax.plot(xs_mm, angle_ratio(k_e, ratio, 1.0, constants.mu_stick), label="γ_stick")
        ax.plot(xs_mm, angle_ratio(k_e, ratio, 1.0, constants.mu_slip), label="γ_slip")
        ax.set_ylabel("γ")
        ax.legend(loc="upper left", fontsize=8)
        right = ax.twinx()
        right.plot(xs_mm, k_e, color="tab:gray", linestyle="--")
        right.set_ylabel("k_e / (Nm/rad), dashed", color="tab:gray")
        right.set_yscale("log")
    ax_length.set(
        title=f"γ over extension length (Fig. 6), d_e = {joint.extension.diameter_mm:g} mm",
        xlabel="l_e / mm",
    )
    ax_diameter.set(
        title=f"γ over extension diameter (Fig. 6), l_e = {joint.extension.length_mm:g} mm",
        xlabel="d_e / mm",
    )
    for ax, value in ((ax_length, joint.extension.length_mm), (ax_diameter, d_e_m / MM)):
        ax.axvline(value, color="tab:red", linewidth=1)


def _natural_frequency(
    ax: Any, joint: JointConfig, model: JointModel, target_time_s: float
) -> None:
    lengths_mm = np.linspace(50.0, 1000.0, 200)
    f_n = extension_natural_frequency_hz(
        joint.material.shear_modulus_gpa * GPA, joint.material.density_kg_m3, lengths_mm * MM
    )
    ax.plot(lengths_mm, f_n, color="black", label="f_n (eq. 40)")
    f_max = float(model.stick_slip_frequency_max_hz(target_time_s))
    ax.axhline(f_max, color="tab:blue", linestyle="--", label="f_ss,max at the target")
    ax.axvline(joint.extension.length_mm, color="tab:red", linewidth=1, label="this extension")
    ax.set_yscale("log")
    ax.set(
        title="natural frequency of the extension (Fig. 7)",
        xlabel="l_e / mm",
        ylabel="f / Hz",
    )
    ax.legend(loc="upper right", fontsize=8)


def draw_validation_figure(name: str, model: Any, metrics: Any, path: Path) -> None:
    """Measured events of one rig run over the envelopes (Figures 13-15) to ``path`` (PNG)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    partial = model.with_relief(PAPER_PARTIAL_RELIEF)
    t_meas = metrics.model_time_s
    t_s = np.linspace(t_meas.min() * 0.95, t_meas.max() * 1.05, 200)
    bands = model.constant_bands()
    fig, axes = plt.subplots(2, 3, figsize=(16, 9))
    fig.suptitle(
        f"rig vs analytical envelopes: {name}, φ̇_m = {model.motor_speed_rad_s:g} rad/s",
        fontsize=13,
    )
    panels = (
        ("f_ss (Fig. 13)", "f_ss / Hz", 1.0, metrics.frequency_hz, "stick_slip_frequency"),
        ("force step ΔF (Fig. 14)", "ΔF / kN", 1e-3, metrics.force_step_n, "force_step"),
        ("torque drop ΔT (Fig. 15)", "ΔT / Nm", 1.0, metrics.torque_drop_nm, "torque_drop"),
    )
    for ax, (title, label, scale, values, stem) in zip(axes[0], panels, strict=True):
        suffix = (
            "_hz" if stem == "stick_slip_frequency" else "_n" if stem == "force_step" else "_nm"
        )
        low, high = f"{stem}_min{suffix}", f"{stem}_max{suffix}"
        _band(
            ax,
            t_s,
            (getattr(model, low)(t_s) * scale, getattr(model, high)(t_s) * scale),
            (getattr(partial, low)(t_s) * scale, getattr(partial, high)(t_s) * scale),
            title,
            label,
            log=True,
        )
        ax.plot(t_meas, values * scale, "o", color="black", markersize=4, label="rig")
        ax.legend(loc="best", fontsize=8)
    for ax, key, values, unit in zip(
        axes[1],
        ("k1", "k2", "k3"),
        (metrics.k1, metrics.k2, metrics.k3),
        ("-", "N·rad/s²", "Nm·rad/s²"),
        strict=True,
    ):
        low, high = getattr(bands, f"{key}_min"), getattr(bands, f"{key}_max")
        ax.axhspan(low, high, color="tab:blue", alpha=0.15, label="band (eqs. 34-39)")
        ax.plot(t_meas, values, "o", color="black", markersize=4, label="rig")
        ax.set_yscale("log")
        ax.set(
            title=f"{key.upper()} over time", xlabel="model time t / s", ylabel=f"{key} / {unit}"
        )
        ax.legend(loc="best", fontsize=8)
    for ax in axes.flat:
        ax.grid(True, which="both", alpha=0.3)
    fig.tight_layout(rect=(0, 0, 1, 0.96))
    with naming(path):
        fig.savefig(path, dpi=90)
    plt.close(fig)
