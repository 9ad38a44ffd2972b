"""Multi-harmonic balance with alternating frequency-time evaluation of the
friction elements (the C core in ``fmu_src``) and arc-length continuation.

Modules: :mod:`.fourier` (basis, ordering, DFT), :mod:`.kinematics` (Q, T and the
cyclic phase of force elements), :mod:`.forces` (force-element interface, linear
elements), :mod:`.aft` (friction links and their exact Jacobian), :mod:`.contact`
(normal contact with lift-off and friction following N, prestress statics),
:mod:`.linear` (dynamic stiffness, receptance), :mod:`.model` (models and their
files), :mod:`.residual` (full and condensed HB residuals), :mod:`.newton`,
:mod:`.continuation` (on any residual callable), :mod:`.frf` (forced-response
curves, peak refinement), :mod:`.timeint` (time-integration reference), :mod:`.plots`.
"""
