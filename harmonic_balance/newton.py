"""Damped Newton solver for square systems R(x) = 0 with a known Jacobian.

Knows nothing about mechanics: ``fun(x) -> (R (N,), J (N, N))``.
Backtracking line search on ``phi = |R|^2 / 2`` (Armijo condition, Dennis & Schnabel
sec. 6.3): a full Newton step is tried first, so convergence stays quadratic near a
solution, and halved while it does not decrease ``phi`` enough.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: Armijo constant: accept a step that gives at least this fraction of the predicted decrease.
ARMIJO = 1e-4
#: Smallest line-search factor before the step is declared a failure.
MIN_ALPHA = 1.0 / 256


class NewtonError(RuntimeError):
    """Newton did not converge; ``reason`` says why, ``x`` is the last iterate."""

    def __init__(self, reason: str, x: np.ndarray, iterations: int, residual: float):
        super().__init__(f"Newton failed after {iterations} iterations: {reason} "
                         f"(|R| = {residual:.3e})")
        self.reason, self.x, self.iterations, self.residual = reason, x, iterations, residual


@dataclass
class NewtonResult:
    x: np.ndarray
    R: np.ndarray
    J: np.ndarray
    iterations: int


def newton(fun, x0, tol: float, max_iter: int = 30) -> NewtonResult:
    """Solve R(x) = 0 to |R|_2 <= tol.

    Parameters
    ----------
    fun : callable x -> (R, J)
    x0 : (N,) array, initial guess
    tol : float, absolute tolerance on the 2-norm of R (callers scale it)
    max_iter : int

    Returns
    -------
    NewtonResult with the converged x, and R, J evaluated there.

    Raises
    ------
    NewtonError (a RuntimeError) with the reason: non-finite residual, singular
    Jacobian, line-search failure, or iteration limit.
    """
    x = np.array(x0, dtype=float)
    R, J = fun(x)
    nr = _norm(R, x, 0)
    for it in range(max_iter + 1):
        if nr <= tol:
            return NewtonResult(x, R, J, it)
        if it == max_iter:
            break
        try:
            dx = np.linalg.solve(J, -R)  # LAPACK gesv; scipy's wrapper costs more at this size
        except np.linalg.LinAlgError:
            raise NewtonError("singular Jacobian", x, it, nr) from None
        if not np.all(np.isfinite(dx)):
            raise NewtonError("singular or non-finite Jacobian", x, it, nr)
        alpha = 1.0
        while True:
            xt = x + alpha * dx
            Rt, Jt = fun(xt)
            nt = np.linalg.norm(Rt) if np.all(np.isfinite(Rt)) else np.inf
            if nt**2 <= (1.0 - 2.0 * ARMIJO * alpha) * nr**2:
                break
            alpha *= 0.5
            if alpha < MIN_ALPHA:
                raise NewtonError("line search found no decrease (non-smooth or no nearby solution)",
                                  x, it, nr)
        x, R, J, nr = xt, Rt, Jt, nt
    raise NewtonError(f"no convergence to {tol:.1e} within {max_iter} iterations", x, max_iter, nr)


def _norm(R, x, it):
    if not np.all(np.isfinite(R)):
        raise NewtonError("non-finite residual at the initial guess", x, it, np.inf)
    return float(np.linalg.norm(R))
