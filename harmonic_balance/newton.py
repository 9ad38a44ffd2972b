"""Globalised Newton solver for square systems R(x) = 0 with a known Jacobian.

Knows nothing about mechanics: ``fun(x) -> (R (N,), J (N, N))``.

Each iteration first tries Newton's step with a backtracking line search on
``phi = |R|^2 / 2`` (Armijo condition, Dennis & Schnabel sec. 6.3): the full step is
tried first, so convergence stays quadratic near a solution. When the line search
stalls (the harmonic-balance residual of a stiff friction contact is only piecewise
smooth: a kink whenever a slip onset moves to another AFT sample, and Newton's
direction is then a descent direction only over a tiny fraction of its length),
the iteration falls back to Levenberg-Marquardt steps with a trust-region update
(More 1978, Nielsen's damping update; Madsen, Nielsen & Tingleff, "Methods for
non-linear least squares problems", 2004, sec. 3.2):
``(J^T J + mu D^T D) p = -J^T R`` with D the running maximum of J's column norms
(invariant to the units of each unknown), ``mu`` shrunk after a good step and grown
after a rejected one. Each accepted LM step decreases phi, so the iteration
converges to a zero of R or a stationary point of phi from anywhere (global
convergence on piecewise-smooth residuals in the sense of Clarke-stationary points);
where it stalls at a non-zero local minimum of phi it says so.
"""
from __future__ import annotations

import sys
from dataclasses import dataclass

import numpy as np

#: Armijo constant: accept a step that gives at least this fraction of the predicted decrease.
ARMIJO = 1e-4
#: Smallest line-search factor before the iteration switches to Levenberg-Marquardt.
MIN_ALPHA = 1.0 / 256
#: Gain ratio (actual / predicted decrease of phi) above which an LM step is accepted.
LM_ACCEPT = 1e-4
#: Damping mu relative to the largest D^T D entry at which LM gives up (the step is
#: then ~1e-12 of the steepest-descent step: phi is stationary).
LM_MU_MAX = 1e12
#: Newton's step relative to |x| below which x counts as converged whatever |R|: the
#: round-off floor. Measured on the Jenkins oscillator at 1e6 k (slip force 0.5 P,
#: c = 1e-4, H = 7, omega = 1, |x| = 3634): |R| cycles at 6e-10 ... 9e-10 (tolerance
#: 1e-10) with |dx| / |x| = 2e-14 ... 8e-14.
STEP_RTOL = 1e-12
#: LM trial steps allowed per iteration before it gives up.
LM_TRIALS = 60


class NewtonError(RuntimeError):
    """Newton did not converge; ``reason`` says why, ``x`` is the last iterate (``iterations``
    None: not counted, where the residual failed)."""

    def __init__(self, reason: str, x: np.ndarray, iterations: int, residual: float):
        after = "" if iterations is None else f" after {iterations} iterations"
        super().__init__(f"Newton failed{after}: {reason} (|R| = {residual:.3e})")
        self.reason, self.x, self.iterations, self.residual = reason, x, iterations, residual


@dataclass
class NewtonResult:
    """x, and R, J evaluated there; ``lu``: the LU factors (:func:`lu_factor`) of the
    Jacobian of the last step (at the iterate before x: O(|x - x_prev|) from J), or None
    when no step was taken. ``J_at_x`` False: J is that last step's Jacobian, not one at x
    (``newton(..., final_jac=False)``)."""

    x: np.ndarray
    R: np.ndarray
    J: np.ndarray
    iterations: int
    lu: tuple | None = None
    J_at_x: bool = True


def lu_factor(A: np.ndarray):
    """LU factors of the square A (n, n) (LAPACK getrf of A^T: a C-ordered A is a
    Fortran-ordered A^T, so nothing is copied; cheaper than ``np.linalg.solve``'s gesv
    from 16 to 700 unknowns), or None when A is exactly singular."""
    from scipy.linalg.lapack import dgetrf

    lu, piv, info = dgetrf(np.asarray(A, dtype=float).T)
    return None if info != 0 else (lu, piv)


def lu_solve(factors, b: np.ndarray) -> np.ndarray:
    """x with A x = b from :func:`lu_factor`'s factors of A (or structured factors with a
    ``solve`` method, e.g. :class:`.block_lu.BlockTridiagonalLU`)."""
    from scipy.linalg.lapack import dgetrs

    if hasattr(factors, "solve"):
        return factors.solve(b)
    x, _ = dgetrs(factors[0], factors[1], b, trans=1)
    return x


def lu_det_sign(factors) -> float:
    """Sign of det(A) from :func:`lu_factor`'s factors (0-based row swaps), or from
    structured factors' ``det_sign``."""
    if hasattr(factors, "det_sign"):
        return factors.det_sign()
    lu, piv = factors
    swaps = np.count_nonzero(piv != np.arange(len(piv))) % 2
    return float((-1.0) ** swaps * np.prod(np.sign(np.diag(lu))))


def newton(fun, x0, tol: float, max_iter: int = 30, x_norm: float = 0.0,
           min_alpha: float = None, lm: bool = True, value=None,
           final_jac: bool = True, factor=None) -> NewtonResult:
    """Solve R(x) = 0 to |R|_2 <= tol, or until Newton's step is below round-off.

    The second test (|dx|_2 <= STEP_RTOL max(|x|_2, x_norm)) ends the iteration when
    x is determined to STEP_RTOL but |R| is held above tol by round-off: a stiff link
    (F = k_0 (u - z), u >> u - z) carries an absolute error ~ eps k_0 |u| in every
    sample.

    Parameters
    ----------
    fun : callable x -> (R, J)
    x0 : (N,) array, initial guess
    tol : float, absolute tolerance on the 2-norm of R (callers scale it)
    max_iter : int
    x_norm : float, size of x for the step test when x is an offset (0: |x|)
    min_alpha : float, smallest line-search factor (default MIN_ALPHA)
    lm : bool, fall back to Levenberg-Marquardt when the line search fails (False:
        fail at once, e.g. in a continuation corrector, which then takes a smaller step)
    value : callable x -> R, optional
        R alone, the same numbers as ``fun(x)[0]`` at less cost: the line search's
        trial points (:func:`line_search`); None: ``fun``.
    final_jac : bool, False (with ``value``): a step that lands within tol is not followed
        by the Jacobian at its point; the result carries the step's own Jacobian and
        factors (``J_at_x`` False), enough for a caller that only needs a tangent or a
        size (a continuation corrector: one Jacobian assembly less per point).
    factor : callable J -> factors, optional
        The LU factorisation of J to use instead of :func:`lu_factor` (a structured one,
        e.g. :func:`.block_lu.factor` behind a problem's ``factorize``); its factors go to
        :func:`lu_solve` and :func:`lu_det_sign`, None from it means singular.

    Returns
    -------
    NewtonResult with the converged x, and R, J evaluated there (see ``final_jac``).

    Raises
    ------
    NewtonError (a RuntimeError) with the reason: non-finite residual, singular
    Jacobian, line-search failure, iteration limit, or a residual that cannot be
    evaluated at an iterate (:func:`_guarded`).
    """
    fun, value = _guarded(fun), _guarded(value)
    x = np.array(x0, dtype=float)
    R, J = fun(x)
    nr = _norm(R, x, 0)
    state = _LMState()
    lu = None
    for it in range(max_iter + 1):
        if nr <= tol:
            return NewtonResult(x, R, J, it, lu)
        if it == max_iter:
            break
        lu = (factor or lu_factor)(J)
        if lu is None:
            raise NewtonError("singular Jacobian", x, it, nr)
        dx = lu_solve(lu, -R)
        if not np.all(np.isfinite(dx)):
            raise NewtonError("singular or non-finite Jacobian", x, it, nr)
        if np.linalg.norm(dx) <= STEP_RTOL * max(np.linalg.norm(x), x_norm):
            x = x + dx  # the last (tiny) step, so a smooth residual keeps quadratic accuracy
            R, J = fun(x)
            return NewtonResult(x, R, J, it + 1, lu)
        step = line_search(fun, x, dx, nr, MIN_ALPHA if min_alpha is None else min_alpha, value,
                           None if final_jac else tol)
        if step is not None and step[2] is None:  # within tol, no Jacobian there
            return NewtonResult(step[0], step[1], J, it + 1, lu, J_at_x=False)
        if step is None and _at_noise_floor(fun, x, R, J, nr, tol, x_norm):
            return NewtonResult(x, R, J, it, lu)
        if step is None:
            if not lm:
                raise NewtonError("no decrease along Newton's direction", x, it, nr)
            step, state = _lm_step(fun, x, R, J, nr, state)
            lu = None  # an LM step: the factors are not the step's
            if step is None:
                raise NewtonError("no decrease, neither along Newton's direction nor by "
                                  "Levenberg-Marquardt steps (a local minimum of |R| that "
                                  "is no solution, or no nearby solution)", x, it, nr)
        x, R, J, nr = step
    raise NewtonError(f"no convergence to {tol:.1e} within {max_iter} iterations", x, max_iter, nr)


def _guarded(f):
    """``f`` with an evaluation failure turned into a :class:`NewtonError`, or None.

    A friction element whose periodic loop does not close within its period limit
    (``fmu_src``'s ``IwanNotConvergedError``: near lift-off of a 3D contact, with the
    normal load varying and the slip in two directions) cannot give R at that x. For the
    solver this is a failed iteration, as a singular Jacobian is, so a continuation
    corrector shortens its step instead of ending the curve. Only that error: any other
    exception is a bug and passes through.
    """
    if f is None:
        return None

    def g(x):
        try:
            return f(x)
        except evaluation_errors() as err:  # evaluated only when f raised
            raise NewtonError(f"the residual cannot be evaluated there ({err})", x, None,
                              np.inf) from err
    return g


def evaluation_errors() -> tuple:
    """The exception types by which a residual says it cannot be evaluated at x (a failed
    iteration, :func:`_guarded`): the friction element's, when its C layer is loaded (a
    residual that never loaded it cannot raise it; no import of the library)."""
    clib = sys.modules.get("fmu_src._clib")
    return () if clib is None else (clib.IwanNotConvergedError,)


#: |R| up to this many times the tolerance may be declared round-off (_at_noise_floor).
NOISE_TOL_FACTOR = 1e3
#: Relative perturbation of x that probes the residual's round-off (4 ulp).
NOISE_REL = 2.0**-50


def _at_noise_floor(fun, x, R, J, nr, tol, x_norm=0.0) -> bool:
    """True when |R| (at most NOISE_TOL_FACTOR tol) is round-off: moving x by a few ulp
    changes R by half its size or more while the linearisation predicts a tenth of that
    at most, so no step can reduce |R| further.

    Measured on the exact AFT (``FrictionLink.exact``) at 1e6 k, H = 21: its harmonics
    carry ~1e-10 of round-off (the phase rounding eps h theta of each harmonic, times the
    stick windows' k_t |u| L), as large as the tolerance, and a homotopy step failed on
    "no decrease" there. One extra evaluation, on a line-search failure only.
    """
    if nr > NOISE_TOL_FACTOR * tol:
        return False
    # a few ulp of the unknowns' size (x_norm when x is an offset, as in a corrector)
    d = NOISE_REL * max(np.abs(x).max(), x_norm) * np.where(np.arange(x.size) % 2, 1.0, -1.0)
    R2, _ = fun(x + d)
    return bool(np.linalg.norm(R2 - R) >= 0.5 * nr and np.linalg.norm(J @ d) <= 0.1 * nr)


def line_search(fun, x, dx, nr, min_alpha=MIN_ALPHA, value=None, done_tol=None):
    """Armijo backtracking along dx; (x, R, J, |R|) or None when alpha < min_alpha.

    ``value`` (x -> R, the same numbers as ``fun(x)[0]``): the trial points are judged by
    R alone and only the accepted one gets its Jacobian (``fun``), so a rejected trial
    costs no Jacobian; nor does an accepted one with |R| <= ``done_tol`` (J None then).
    Also the sparse ring solver's (:mod:`.bladed_disk.ring_solve`): ``J`` is whatever
    ``fun`` returns, dense or sparse.
    """
    alpha = 1.0
    while alpha >= min_alpha:
        xt = x + alpha * dx
        Rt, Jt = (value(xt), None) if value is not None else fun(xt)
        nt = np.linalg.norm(Rt) if np.all(np.isfinite(Rt)) else np.inf
        if nt**2 <= (1.0 - 2.0 * ARMIJO * alpha) * nr**2:
            if Jt is None and not (done_tol is not None and nt <= done_tol):
                Rt, Jt = fun(xt)
            return xt, Rt, Jt, nt
        alpha *= 0.5
    return None


class _LMState:
    """Damping mu, its growth factor nu and the column scaling D kept between iterations."""

    def __init__(self):
        self.mu, self.nu, self.d2 = None, 2.0, None


def _lm_step(fun, x, R, J, nr, st):
    """One accepted Levenberg-Marquardt step from x, or (None, st) when none decreases phi."""
    g = J.T @ R
    A = J.T @ J
    d2 = np.diag(A).copy()
    st.d2 = d2 if st.d2 is None else np.maximum(st.d2, d2)
    d2 = np.maximum(st.d2, 1e-300 * max(st.d2.max(), 1e-300))
    if st.mu is None:
        st.mu = 1e-3  # relative to D^T D: a nearly Gauss-Newton first trial
    for _ in range(LM_TRIALS):
        try:
            p = np.linalg.solve(A + st.mu * np.diag(d2), -g)
        except np.linalg.LinAlgError:
            p = None
        if p is not None and np.all(np.isfinite(p)):
            xt = x + p
            Rt, Jt = fun(xt)
            nt = np.linalg.norm(Rt) if np.all(np.isfinite(Rt)) else np.inf
            pred = -(p @ g) - 0.5 * (p @ (A @ p))  # decrease of phi predicted by the model
            rho = (0.5 * nr**2 - 0.5 * nt**2) / pred if pred > 0 else -1.0
            if rho > LM_ACCEPT:
                st.mu *= max(1.0 / 3.0, 1.0 - (2.0 * rho - 1.0) ** 3)
                st.nu = 2.0
                return (xt, Rt, Jt, nt), st
        st.mu *= st.nu
        st.nu *= 2.0
        if st.mu > LM_MU_MAX:
            break
    st.mu, st.nu = None, 2.0
    return None, st


def _norm(R, x, it):
    if not np.all(np.isfinite(R)):
        raise NewtonError("non-finite residual at the initial guess", x, it, np.inf)
    return float(np.linalg.norm(R))
