"""A first solution that does not depend on where the sweep starts: homotopy in the forcing level.

Why: a friction link whose contact stiffness is 30 k or more has a stuck linear
response (the natural starting guess) far from the slipping solution: at
m = k = 1, c = 0.04, slip force 0.5, forcing 1 and contact stiffness 30 the stuck
amplitude at omega = 0.5 is 0.033 m, the solution's about 0.9 m, and the residual is
piecewise smooth (a kink whenever a slip onset moves to another AFT sample), so
Newton's step from the stuck guess (50 x the guess's size) is no descent direction
beyond 1e-4 of its length: "line search found no decrease" (measured).

How: the HB residual is affine in the excitation, ``R(x; lam) = N(x) - lam f``
(f = the excitation's image in the residual: F_ext for the full residual, the
linear response X_lin for the condensed one). At a small enough level lam0 every
link sticks and the stuck linear solution ``lam0 x_stuck`` is exact (a Jenkins
element) or Newton's first guess converges (an Iwan element's weakest slider);
arc-length continuation in lam (the same :func:`continuation.continuation`) then
carries it to lam = 1 through the stick-slip transition and any fold. This is the
"continuation in the forcing level" start of NLvib's examples and the homotopy
start of pyHarm, without their hand-picked first steps.

``f`` is obtained from the residual itself, without knowing its type: R is affine
in the excitation, so ``f = R(x; 1) - R(x; 2)`` at any x (the same model with the
excitation doubled), one residual evaluation without Jacobian.
"""
from __future__ import annotations

from dataclasses import replace

import numpy as np

from .continuation import ContinuationError, continuation
from .newton import NewtonError, newton

#: Levels tried for the homotopy's first point, largest first: the first at which
#: Newton converges from the stuck guess starts the continuation.
START_LEVELS = tuple(10.0 ** -k for k in range(1, 9))
#: Largest scaled step of the homotopy. The scaled x has norm ~sqrt(N) (each unknown
#: scaled by the RMS), lam runs over [lam0, 1]: 1.0 took 30-40 points on the
#: reference sdof at contact stiffness 30 (0.04 took > 400, 0.3 200).
HOMOTOPY_DS_MAX = 1.0


class HomotopyError(RuntimeError):
    """The homotopy did not reach the requested excitation level."""


def forcing_vector(make_residual_at, model, x, omega):
    """Image f (N,) of the excitation in the residual at ``omega``: R(x; lam) = N(x) - lam f.

    Parameters
    ----------
    make_residual_at : callable Model -> residual callable (x, omega, jac=False) -> R
    model : harmonic_balance.model.Model
    x : (N,) array, any point (R is affine in the excitation)
    omega : float [rad/s]
    """
    doubled = replace(model, forcing={h: 2.0 * f for h, f in model.forcing.items()})
    r1 = make_residual_at(model)(x, omega, jac=False)
    r2 = make_residual_at(doubled)(x, omega, jac=False)
    return r1 - r2


def solve_with_homotopy(fun, x_stuck, f, tol, max_points=400):
    """Solve ``fun(x) = 0`` (full excitation) by continuation in the excitation level.

    Parameters
    ----------
    fun : callable x -> (R (N,), dR/dx (N, N)), the residual at the full excitation
    x_stuck : (N,) array, stuck linear solution at the full excitation
    f : (N,) array, excitation image (:func:`forcing_vector`)
    tol : float, absolute tolerance on |R|_2 at the full excitation
    max_points : int

    Returns
    -------
    x : (N,) array, the solution at the full excitation
    info : dict with ``start_level``, ``points``, ``iterations`` of the homotopy

    Raises
    ------
    HomotopyError with the level reached and why.
    """
    def fun_lam(x, lam):
        R, J = fun(x)
        return R + (1.0 - lam) * f, J, -f

    lam0, first = _first_level(fun_lam, x_stuck, tol)
    try:
        br = continuation(fun_lam, first, lam0, 1.0, tol, ds=0.1, ds_max=HOMOTOPY_DS_MAX,
                          max_points=max_points, x_scale=_rms(x_stuck), tolerance=None)
    except ContinuationError as err:
        raise HomotopyError(f"homotopy in the excitation level failed: {err}") from None
    info = {"start_level": lam0, "points": len(br.lam), "iterations": int(sum(br.iterations))}
    return br.x[-1], info


def _first_level(fun_lam, x_stuck, tol):
    """Largest level of START_LEVELS at which Newton converges from lam x_stuck."""
    for lam in START_LEVELS:
        try:
            res = newton(lambda z, lam=lam: fun_lam(z, lam)[:2], lam * x_stuck, tol)
        except NewtonError:
            continue
        return lam, res.x
    raise HomotopyError("homotopy in the excitation level found no converged start even "
                        f"at level {START_LEVELS[-1]:g}")


def _rms(x):
    return float(np.sqrt(np.mean(np.square(x))))
