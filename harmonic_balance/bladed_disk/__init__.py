"""Bladed disks with underplatform dampers: cyclic-sector and full-ring harmonic balance.

Modules: :mod:`config` (TOML, bundled UPD-24), :mod:`blade` (the blade's reduced
matrices with named platform DOFs: built-in lumped UPD-24, .npz or Matrix Market,
Craig-Bampton), :mod:`sector` (linear sector, kinematics, linear limits), :mod:`hb`
(nonlinear sector harmonic balance), :mod:`ring` and :mod:`timeint` (the short ring);
the mistuned full ring: :mod:`mistuning` (patterns, linear ring), :mod:`ring_hb` (sparse
harmonic balance of all N_b sectors), :mod:`ring_solve` (Newton, sweep, per-blade peaks).
"""
