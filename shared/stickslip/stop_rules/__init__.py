"""The stop rules, one small class each; :mod:`..stop_policy` checks them in the order it states.

Files:

- :mod:`.stop`                what a rule says when it fires: reason, detail, predicted landing
- :mod:`.hard_limits`         torque / force / angle limit held for ``limit_samples`` (per sample)
- :mod:`.target_rule`         target reached, its ramp projection, the torque halt plan (per sample)
- :mod:`.plateau_rule`        the plateau closest to the target, eqs. 64/65 (per event)
- :mod:`.intensity_rule`      the process intensity over I_max, eq. 70 (per event)
- :mod:`.constant_band_rule`  K1-K3 out of their band, eq. 71 (per event)
"""
