"""Stability of periodic HB solutions by Hill's method on the AFT Jacobian.

A perturbation ``y(t) = exp(lam t) p(t)`` of a periodic solution, with p periodic
(harmonics P in the basis of :mod:`fourier`), satisfies the linearised equation of
motion ``M y'' + C y' + K y + (dF/dx) y = 0``. Velocity and acceleration of y are
``exp(lam t) (lam + omega D_theta) p`` and ``exp(lam t) (lam + omega D_theta)^2 p``,
so in harmonics (Hill's quadratic eigenproblem; Peletan et al., Nonlinear Dyn. 2013;
NLvib's ``Hill`` stability)::

    [ J(omega) + lam Delta_1 + lam^2 Delta_2 ] P = 0,
    Delta_1 = 2 omega D_theta (x) M + I (x) C,   Delta_2 = I (x) M

with J(omega) = dR/dx, the HB Jacobian of the full residual (the friction part is
the exact AFT Jacobian of the sampled loop, the rate-independent tangent). The
truncated problem has 2 N eigenvalues; the Floquet exponents are defined modulo
i omega, and the 2 n of them with the smallest |Im lam| are the well-resolved ones
(the others are copies shifted by multiples of i omega, badly resolved near the
truncation). The solution is stable when their real parts are all below
``STABLE_TOL`` times omega (a neutral exponent, e.g. the zero exponent of the
sliders' mean position, counts as stable).
"""
from __future__ import annotations

import numpy as np

#: Largest real part of a Floquet exponent, relative to omega, still counted as
#: stable: round-off of the eigensolver on the (2N)^2 companion matrix is ~1e-12;
#: neutral exponents (a sliding mean position) land at |Re| ~ 1e-9 relative.
STABLE_TOL = 1e-6


def hill_matrices(linear, basis, omega: float, V=None):
    """Delta_1, Delta_2 (N, N) of Hill's problem for a matrix model (module docstring).

    V : (N, N) array or None, the force elements' linear dashpots on the unknowns
        (``FullResidual.viscous_operator()``): their velocity term adds ``lam V``.
    """
    if linear.M is None:
        raise ValueError("Hill's method needs the mass matrix (a matrix model)")
    I = np.eye(basis.nb)
    d1 = 2.0 * omega * np.kron(basis.dtheta, linear.M) + np.kron(I, linear.C)
    if V is not None:
        d1 = d1 + V
    d2 = np.kron(I, linear.M)
    return d1, d2


def floquet_exponents(J, d1, d2, n: int, omega: float) -> np.ndarray:
    """The 2 n Floquet exponents lam (complex) of Hill's problem with smallest |Im|.

    Parameters
    ----------
    J : (N, N) array, dR/dx at the solution
    d1, d2 : (N, N) arrays, :func:`hill_matrices`
    n : int, DOFs of the model
    omega : float [rad/s]
    """
    N = J.shape[0]
    # Companion linearisation: z = (P, lam P); d2 invertible (M is SPD).
    A = np.zeros((2 * N, 2 * N))
    A[:N, N:] = np.eye(N)
    A[N:, :N] = -np.linalg.solve(d2, J)
    A[N:, N:] = -np.linalg.solve(d2, d1)
    lam = np.linalg.eigvals(A)  # LAPACK geev, as scipy's, without its import
    order = np.argsort(np.abs(lam.imag))
    return lam[order[:2 * n]]


def is_stable(J, linear, basis, omega: float, V=None) -> tuple[bool, float]:
    """(stable, largest real part of the retained Floquet exponents [1/s])."""
    d1, d2 = hill_matrices(linear, basis, omega, V)
    lam = floquet_exponents(J, d1, d2, linear.n, omega)
    worst = float(lam.real.max())
    return bool(worst <= STABLE_TOL * omega), worst


#: Largest number of points between two Hill checks in the reduced mode of
#: :func:`along_branch`: a guard against a change that leaves det(dR/dx) alone (a
#: complex pair or a multiplier -1 leaving the unit circle) between checks that agree.
CHECK_SPACING = 25


def along_branch(n: int, det_sign, check, anchors=(), spacing: int = CHECK_SPACING):
    """Stability of the n points of a branch from Hill checks where it can change.

    Hill's method (``check(i) -> bool``) runs at the first and last point, on both sides
    of every sign change of det(dR/dx) (``det_sign`` (n,): a real Floquet multiplier
    crosses +1 there: a fold or a branch point; 0 = unknown counts as its own sign), at
    the ``anchors`` (e.g. the peaks) and at least every ``spacing`` points. Between two
    checks that agree every point gets their answer; where they differ (a change det
    does not see: a complex pair, a multiplier at -1) the stretch is bisected down to
    neighbouring points, so the change is located exactly.

    Returns
    -------
    stable : list of bool (n,), checks : int (Hill eigenproblems solved)
    """
    known = {}

    def at(i):
        if i not in known:
            known[i] = bool(check(i))
        return known[i]

    marks = {0, n - 1} | {int(i) for i in anchors if 0 <= i < n} | set(range(0, n, max(1, spacing)))
    marks |= {j for i in range(1, n) if det_sign[i] != det_sign[i - 1] for j in (i - 1, i)}
    marks = sorted(marks)
    out = [False] * n
    stack = list(zip(marks, marks[1:]))
    for i in marks:
        at(i)
    while stack:
        a, b = stack.pop()
        if at(a) == at(b):
            out[a:b + 1] = [known[a]] * (b - a + 1)
        elif b - a > 1:
            m = (a + b) // 2
            stack += [(a, m), (m, b)]
    for i, v in known.items():
        out[i] = v
    return out, len(known)
