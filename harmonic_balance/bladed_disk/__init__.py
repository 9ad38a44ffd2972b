"""Tuned bladed disk with underplatform dampers: cyclic-sector harmonic balance.

Modules: :mod:`config` (TOML, bundled UPD-24), :mod:`sector` (linear sector,
kinematics, linear limits), :mod:`hb` (nonlinear sector harmonic balance).
"""
