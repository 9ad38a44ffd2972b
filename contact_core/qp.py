"""Bounded convex quadratic programmes of the contact solves, with a KKT check.

Both contact problems are, at fixed rigid motion, the strictly convex QP

    min_x  1/2 x^T K x - x^T b    s.t.  lo <= x <= hi,

K (m, m) symmetric positive definite, gradient g = K x - b:

* normal (thesis A.1): x = f the nodal forces, K = C the normal compliance,
  b = -(h - R_q q), bounds [0, inf); g is the gap, and the KKT conditions are
  Signorini's g >= 0, f >= 0, f g = 0;
* tangential (thesis A.2): x = q the nodal tangential forces, K = W C, b = W r,
  bounds [-mu f, mu f]; g = -W ds, and the KKT conditions are Coulomb's law
  (stick nodes do not slip, slip nodes carry mu f against the slip).

One solver, Bertsekas' projected Newton method (SIAM J. Control Optim. 20,
1982): variables at a bound whose gradient pushes outwards are held; on the
others a Newton step (one dense Cholesky solve of K on the free set: the
thesis's contact-set solve A.17 / stick-set solve A.40) is projected onto the
box and shortened by an Armijo rule. The objective falls at every iteration,
so no set recurs (the plain exchange of sets by their violations cycles on
dense half-space compliances); on a QP the full step lands exactly on the
solution once the sets are right, 1-3 iterations when warm started.
Should it not converge within ``max_iter`` iterations, scipy's bounded-variable
least squares (``lsq_linear``, method "bvls", a finite active-set method) on
the Cholesky form of the QP takes over (``fallback``), or RuntimeError.

Library alternatives measured (``examples/bench_contact.py --qp``): scipy's
``nnls`` and ``lsq_linear`` need the Cholesky factor of the whole K and have no
warm start, so every force-control Newton step restarts from scratch; measured
numbers in ``contact_core.normal``.

Every result is checked by :func:`check_kkt` (RuntimeError with the violation).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import linalg, optimize

#: Armijo sufficient-decrease constant and its backtracking limit.
ARMIJO_SIGMA = 1e-4
ARMIJO_STEPS = 60


@dataclass
class QPResult:
    """Solution of a bounded QP.

    Attributes
    ----------
    x : ndarray, shape (m,)       the minimiser
    g : ndarray, shape (m,)       gradient K x - b there
    free : ndarray of bool (m,)   variables strictly inside their bounds
    iterations : int              projected Newton iterations (+ BVLS ones if it took over)
    factor : tuple or None        ``cho_factor`` of K on ``free`` if the last step computed it
    """

    x: np.ndarray
    g: np.ndarray
    free: np.ndarray
    iterations: int
    factor: tuple | None = None


def kkt_free(x, g, lo, hi, gtol) -> np.ndarray | None:
    """The free (interior) mask if (x, g) is a KKT point within ``gtol``, else None."""
    at_lo, at_hi = x <= lo, x >= hi
    free = ~(at_lo | at_hi)
    ok = (np.all(np.abs(g[free]) <= gtol) and np.all(g[at_hi] <= gtol)
          and np.all(g[at_lo] >= -gtol))
    return free if ok else None


def solve(K, b, lo, hi, x0=None, *, gtol: float, max_iter: int = 200,
          fallback: bool = True, name: str = "bounded QP") -> QPResult:
    """Projected Newton solve of min 1/2 x'Kx - x'b, lo <= x <= hi (module docstring).

    Parameters
    ----------
    K : ndarray (m, m) SPD;  b, lo, hi : ndarray (m,) (lo may be 0, hi may be inf)
    x0 : ndarray (m,), optional   warm start (clipped to the box; default lo clipped at 0)
    gtol : float                  gradient tolerance of the stopping test [units of g]
    max_iter : int                projected Newton iterations before the fallback
    fallback : bool               BVLS after ``max_iter`` (else RuntimeError)
    name : str                    what is solved, for error messages

    Returns
    -------
    QPResult (not yet KKT-checked by the caller's tolerances: see ``check_kkt``)
    """
    dinv = 1.0 / np.diag(K)
    x = np.clip(np.zeros(b.size) if x0 is None else x0, lo, hi)
    g = K @ x - b
    F, cho = None, None
    for it in range(max_iter + 1):
        free = kkt_free(x, g, lo, hi, gtol)
        if free is not None:  # reuse the last factor if it is the free set's
            same = F is not None and np.array_equal(F, free)
            return QPResult(x, g, free, it, cho if same else None)
        if it == max_iter:
            break
        pg = np.abs(x - np.clip(x - dinv * g, lo, hi))
        eps = min(1e-3 * _finite_scale(lo, hi, x), float(pg.max()))
        held = ((x <= lo + eps) & (g > 0)) | ((x >= hi - eps) & (g < 0))
        step = -dinv * g
        F, cho = ~held, None
        if F.any():
            cho = linalg.cho_factor(K[np.ix_(F, F)], check_finite=False)
            step[F] = -linalg.cho_solve(cho, g[F], check_finite=False)
        x, g = _armijo(K, b, lo, hi, x, g, step, F)
    if not fallback:
        viol = _violation(x, g, lo, hi)
        raise RuntimeError(f"{name} did not converge in {max_iter} iterations "
                           f"(largest KKT violation {viol:.3e})")
    return _bvls(K, b, lo, hi, max_iter, name)


def _finite_scale(lo, hi, x) -> float:
    """A force scale of the box: the largest finite bound, else the largest |x|."""
    bounds = np.abs(np.concatenate([lo, hi]))
    bounds = bounds[np.isfinite(bounds) & (bounds > 0)]
    return float(bounds.max()) if bounds.size else max(float(np.abs(x).max()), 1e-300)


def _armijo(K, b, lo, hi, x, g, step, F):
    """Projected step with Armijo backtracking (Bertsekas' condition)."""
    f0 = 0.5 * x @ (K @ x) - b @ x
    alpha = 1.0
    for _ in range(ARMIJO_STEPS):
        xa = np.clip(x + alpha * step, lo, hi)
        Kxa = K @ xa
        fa = 0.5 * xa @ Kxa - b @ xa
        predicted = -alpha * (g[F] @ step[F]) + g[~F] @ (x[~F] - xa[~F])
        if f0 - fa >= ARMIJO_SIGMA * predicted:
            return xa, Kxa - b
        alpha *= 0.5
    return xa, Kxa - b  # the step has become negligible; the caller re-checks KKT


def _bvls(K, b, lo, hi, iterations, name) -> QPResult:
    """Bounded-variable least squares on the Cholesky form |L'x - L^-1 b|^2 of the QP."""
    L = linalg.cholesky(K, lower=True)
    rhs = linalg.solve_triangular(L, b, lower=True)
    res = optimize.lsq_linear(L.T, rhs, bounds=(lo, hi), method="bvls", tol=1e-14)
    if not res.success:
        raise RuntimeError(f"{name} did not converge (BVLS: {res.message})")
    x = np.clip(res.x, lo, hi)
    span = np.where(np.isfinite(hi), np.abs(hi), np.abs(x))
    free = (x > lo + 1e-12 * span) & (x < hi - 1e-12 * span)
    return QPResult(x, K @ x - b, free, iterations + int(res.nit), None)


def _violation(x, g, lo, hi) -> float:
    free = (x > lo) & (x < hi)
    parts = [np.abs(g[free]), -g[(x <= lo)], g[(x >= hi)], lo - x, x - hi]
    return float(max((p.max() for p in parts if p.size), default=0.0))


def check_kkt(x, g, lo, hi, free, *, xtol: float, gtol: float, name: str = "bounded QP",
              x_unit: str = "", g_unit: str = "") -> None:
    """Raise RuntimeError unless x is a KKT point of the box QP within the tolerances.

    Parameters
    ----------
    x, g : ndarray (m,)   solution and its gradient K x - b
    lo, hi : ndarray (m,) bounds
    free : ndarray of bool (m,)  variables declared interior (the rest at a bound)
    xtol, gtol : float    allowed bound violation of x and stationarity error of g
    """
    over = max(float(np.max(lo - x, initial=0.0)), float(np.max(x - hi, initial=0.0)))
    if over > xtol:
        raise RuntimeError(f"{name}: a variable leaves its bounds by {over:.3e} {x_unit} "
                           f"(KKT check failed)")
    if free.any() and np.abs(g[free]).max() > gtol:
        raise RuntimeError(f"{name}: stationarity violated by {np.abs(g[free]).max():.3e} "
                           f"{g_unit} at an interior variable (KKT check failed)")
    bound = ~free & (lo < hi)           # a variable pinned by lo == hi takes any gradient
    at_lo = bound & (np.abs(x - lo) <= np.abs(x - hi))
    wrong = np.concatenate([-g[at_lo], g[bound & ~at_lo]])
    if wrong.size and wrong.max() > gtol:
        raise RuntimeError(f"{name}: a variable at a bound is pushed inwards by {wrong.max():.3e} "
                           f"{g_unit} (KKT check failed)")
