"""FE contact models of two elastic bodies (thesis Appendix A).

Bodies and meshes (scikit-fem), static (Guyan) condensation onto the contact and
distant nodes, the active-set normal solve and the stick/slip tangential solve.
Never imports ``harmonic_balance``.
"""
