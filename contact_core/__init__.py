"""FE contact models of two elastic bodies (thesis Appendix A).

Bodies and meshes (scikit-fem), static (Guyan) condensation onto the contact and
distant nodes, the active-set normal solve and the stick/slip tangential solve.
Never imports ``harmonic_balance``.

Normal-contact modules, in pipeline order:

``spec``       ContactSpec: pair, materials, model variant, grid, zone sizing
``bodies``     one class per body kind: zone, meshes, gap, references, labels
``mesh``       graded structured hex meshes (blocks, real half-sphere/half-cylinder)
``assembly``   vectorised Hex8 elasticity stiffness (equal to scikit-fem's)
``linsolve``   sparse Cholesky (CHOLMOD, optional) / SuperLU compliance blocks
``condense``   ``condense(spec, directions, cache)`` -> ``condensed.CondensedContact``
``byo``        the same from imported stiffness matrices (.mtx / .npz)
``cache``      the cache protocol and the on-disk default of condensed matrices
``qp``         the bounded-QP solver (projected Newton, BVLS fallback) and its KKT check
``normal``     LCP / active-set solve, force and displacement control, k_n
``report``     derived results (contact radius, half-widths, shares)
``api``        one-call analysis used by ``damper normal`` and the examples
``hertz``      analytic references
"""
