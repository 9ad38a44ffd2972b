"""Multi-harmonic balance with alternating frequency-time evaluation of the
friction elements (the C core in ``fmu_src``) and arc-length continuation.

Modules: :mod:`.fourier` (basis, ordering, DFT), :mod:`.aft` (friction forces and
their exact Jacobian), :mod:`.linear` (dynamic stiffness, receptance),
:mod:`.model` (models and their files), :mod:`.residual` (full and condensed HB
residuals), :mod:`.newton`, :mod:`.continuation` (on any residual callable),
:mod:`.frf` (forced-response curves, peak refinement), :mod:`.timeint`
(time-integration reference), :mod:`.plots`.
"""
