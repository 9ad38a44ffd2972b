"""The scaled augmented system of a continuation step and its two correctors.

Knows nothing about mechanics: ``fun(x, lam) -> (R (N,), dR/dx (N, N), dR/dlam (N,))``,
optionally with ``fun.value(x, lam) -> R`` (R alone, at less cost) and
``fun.factorize(A) -> factors`` (an LU of the step's matrices that knows their structure,
e.g. :func:`.block_lu.chain_factorizer`'s; else the dense :func:`.newton.lu_factor`).

In scaled variables y = (x / s_x, lam / s_lam) the step's systems are (Allgower & Georg,
Numerical Continuation Methods, ch. 2 and 6): the tangent ``[R_x s_x, R_lam s_lam; t_prev^T] t
= [0; 1]``; the pseudo-arclength corrector, Newton on R = 0 and ``normal . (y - y_pred) = 0``
(:meth:`ScaledSystem.correct`); and its fallback, Newton on R = 0 at the predictor's parameter
(:meth:`ScaledSystem.correct_fixed`). The step control around them is :mod:`.continuation`'s.
"""
from __future__ import annotations

import numpy as np

from .newton import NewtonError, lu_det_sign, lu_factor, lu_solve, newton

#: Newton options of the correctors: no Levenberg-Marquardt fallback and a short line
#: search (a failing corrector is retried with half the step, which is cheaper).
#: Measured on the Jenkins FRF at 1e6 k, H = 15, 0.5 -> 0.8 rad/s: 16807 residual
#: evaluations for 577 points with the full globalisation (66 % in failed correctors),
#: 9894 for 579 points with these options.
CORRECTOR_NEWTON = {"lm": False, "min_alpha": 0.1}
#: Newton options of the fixed-parameter fallback inside a step: the same short
#: globalisation (a failing fallback is followed by a shorter step, as a failing plane
#: corrector is). Measured on chain5 (:mod:`.bench_models`) at H = 15: with
#: Levenberg-Marquardt and the long line search 57 failed fallbacks cost 70 evaluations
#: each (4008 of the curve's 6739); with these options 3449 evaluations for 272 points
#: against 6739 for 287, the same refined peak.
FIXED_NEWTON = {"lm": False, "min_alpha": 0.1}
#: Corrector iteration limit inside the continuation (a step is retried smaller).
CORRECTOR_ITER = 12


class ScaledSystem:
    """The scaled augmented problem around fixed scales (s_x, s_lam)."""

    def __init__(self, fun, s_x, s_lam, tol):
        self.fun, self.s_x, self.s_lam, self.tol = fun, s_x, s_lam, tol
        # a structured LU of R's Jacobian, with or without the plane row and the R_lam
        # column (e.g. block tridiagonal: :mod:`.block_lu`), when the problem offers one
        self.factor = getattr(fun, "factorize", None)

    def jac(self, y, row=None):
        """R and the scaled Jacobian [R_x s_x, R_lam s_lam] (N, N + 1), with ``row`` (N + 1,)
        appended as its last row when given (the corrector's plane: one (N + 1)^2 array
        written once, not stacked from copies)."""
        R, Jx, Jl = self.fun(y[:-1] * self.s_x, y[-1] * self.s_lam)
        n = Jx.shape[0]
        J = np.empty((n + (row is not None), Jx.shape[1] + 1))
        np.multiply(Jx, self.s_x, out=J[:n, :-1])
        J[:n, -1] = Jl * self.s_lam
        if row is not None:
            J[n] = row
        return R, J

    def value(self, y):
        """R alone at y (``fun.value``), or None when ``fun`` has no such method."""
        f = getattr(self.fun, "value", None)
        return None if f is None else f(y[:-1] * self.s_x, y[-1] * self.s_lam)

    @property
    def has_value(self) -> bool:
        return callable(getattr(self.fun, "value", None))

    def tangent(self, J, t_prev, factors=None):
        """Unit tangent t (N+1,) with t . t_prev > 0, the sign of det([J; t^T]) and the
        sign of det(J_x) (J without its last column). ``factors``: LU factors
        (:func:`.newton.lu_factor`) of a matrix to use for [J; t_prev] (the corrector's
        last one, whose plane row is t_prev: its Jacobian differs from J by the last
        Newton step), else [J; t_prev] is factored.

        The first sign is the branch's orientation (Allgower & Georg, sec. 2.1): it stays
        the same along a regular branch, through turning points and peaks, whatever the
        scaling (positive column scales change det([J; t]) by a positive factor). The
        second is free: by Cramer's rule the last component of the solution of
        [J; t_prev] t = e_(N+1) is det(J_x) / det([J; t_prev]).
        """
        if factors is None:
            factors = (self.factor or lu_factor)(np.vstack([J, t_prev]))
            if factors is None:
                raise np.linalg.LinAlgError("singular extended Jacobian")
        rhs = np.zeros(J.shape[0] + 1)
        rhs[-1] = 1.0
        t = lu_solve(factors, rhs)
        if not np.all(np.isfinite(t)):
            raise np.linalg.LinAlgError("non-finite tangent")
        n = np.linalg.norm(t)
        # det is linear in the last row, det([J; w]) = w . c with c parallel to t (the
        # cofactors), so det([J; t]) has the sign of det([J; t_prev]) (t . t_prev > 0),
        # which the LU gives.
        sign = lu_det_sign(factors)
        return t / n, sign, float(np.sign(t[-1]) * sign)

    def correct(self, y_pred, normal, max_iter=CORRECTOR_ITER, start=None):
        """Newton on R = 0 and normal . (y - y_pred) = 0 from y_pred (+ ``start``, an
        offset in the plane: a better first guess of the same point).

        The unknown is the offset d = y - y_pred, so the plane equation carries no
        round-off of |y| (which would otherwise floor |R| near tol when y is large
        in scaled units, e.g. during peak refinement).
        """
        def aug(d):
            R, J = self.jac(y_pred + d, normal)
            return np.append(R, normal @ d), J

        def value(d):
            return np.append(self.value(y_pred + d), normal @ d)
        d0 = np.zeros_like(y_pred) if start is None else start
        # no Jacobian at the converged point: the step's tangent there comes from the
        # factors of the last iteration (_step), the only use of it
        res = newton(aug, d0, self.tol, max_iter, np.linalg.norm(y_pred),
                     value=value if self.has_value else None, final_jac=False,
                     factor=self.factor, **CORRECTOR_NEWTON)
        res.x = y_pred + res.x
        return res

    def correct_fixed(self, y_pred, max_iter=CORRECTOR_ITER, options=None):
        """Newton on R = 0 at the predicted parameter (natural-parameter corrector), or None.

        Fallback of :meth:`correct`: where the branch crosses a kink of the piecewise-
        smooth residual (a stiff slider's slip onset moving to the next AFT sample),
        Newton on the pseudo-arclength system can cycle between the two linear pieces
        (measured on the Jenkins FRF at 1e4 k near 0.545 rad/s: |R| stuck at 1e-7-1e-3
        for every step size down to 1e-6) while Newton at fixed parameter from the
        same predictor converges in 2 iterations. The augmented Jacobian returned
        carries the plane row ``e_lam`` (only J[:-1] is used by the caller). ``options``:
        Newton's globalisation (default FIXED_NEWTON).
        """
        lam = y_pred[-1]
        e = np.zeros(len(y_pred))
        e[-1] = 1.0
        last = {}  # the augmented Jacobian of the last evaluation, reused at the solution

        def fixed(d):
            R, J = self.jac(np.append(y_pred[:-1] + d, lam), e)
            last["d"], last["J"] = d.copy(), J
            return R, J[:-1, :-1]

        def value(d):
            return self.value(np.append(y_pred[:-1] + d, lam))
        try:
            res = newton(fixed, np.zeros(len(y_pred) - 1), self.tol, max_iter,
                         np.linalg.norm(y_pred[:-1]), value=value if self.has_value else None,
                         factor=self.factor, **(FIXED_NEWTON if options is None else options))
        except NewtonError:
            return None
        if np.array_equal(last["d"], res.x):  # Newton's final Jacobian is at its solution
            J = last["J"]
        else:
            J = self.jac(np.append(y_pred[:-1] + res.x, lam), e)[1]
        res.x = np.append(y_pred[:-1] + res.x, lam)
        res.J = J
        res.lu = None  # factors of the fixed-parameter system, not of [J; t]
        return res
