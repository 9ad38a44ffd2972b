"""Normal contact solve on condensed compliances (thesis Appendix A.1).

Symbols (SI units): n contact nodes of the modelled part; C (n, n) combined
normal compliance [m/N]; h (n,) initial gap [m]; R_q (n, r) closing per rigid DOF;
q (r,) rigid DOFs (approach delta [m], rotation theta [rad]); f (n,) compressive
nodal forces [N]; g = h - R_q q + C f (n,) gap [m]; m (n,) full-model weights.

For given q the contact problem is the linear complementarity problem

    g = C f + (h - R_q q) >= 0,  f >= 0,  f g = 0,

equivalently the strictly convex QP  min 1/2 f'Cf + f'(h - R_q q), f >= 0 (C is
symmetric positive definite). For a trial contact set P the thesis reduces the
stiffness onto P (eqs A.12-A.15: nodes outside carry no force); in compliance
form that reduction is simply the sub-block C_PP, so each trial costs one dense
Cholesky solve C_PP f_P = (R_q q - h)_P (the gap closes on P, eq. A.17). The
thesis's active-set idea (nodes in tension leave the contact, penetrating nodes
re-enter) is organised as the projected Newton method of ``contact_core.qp``
(shared with the tangential solve): every step is that contact-set solve,
projected onto f >= 0 and damped so that the QP objective falls, so no set can
recur and the iteration cannot cycle; many nodes enter or leave per step.
Measured against the Lawson-Hanson loop it replaces and scipy's ``nnls`` /
``lsq_linear`` (bvls) on the Cholesky form, one displacement-controlled solve
at the 200 N / 350 N bench loads (1 BLAS thread): sphere 21x21 real (121
nodes) 4.0 / 0.8 / 2.7 / 23 ms, sphere 41x41 half-space (441 nodes)
32 / 30 / 136 / 337 ms, cylinder 21x21 (275 nodes) 11 / 14 / 31 / 93 ms; all
agree to 1e-14. The library solvers refactor the whole C each call and cannot
be warm started across force-control Newton steps.

Tolerances: penetration and the gap on contact nodes <= ``GAP_RTOL`` *
max|h - R_q q| (no tension holds exactly: f = 0 off the active set, f > 0 on
it), checked after every solve (``qp.check_kkt``); force control meets its
targets to ``FORCE_RTOL``.
"""
from __future__ import annotations

import contextlib
import functools
from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla

from . import qp
from .condensed import CondensedContact

#: Allowed penetration relative to the largest effective gap magnitude.
GAP_RTOL = 1e-10
#: Relative accuracy of force control (force and moment).
FORCE_RTOL = 1e-9
#: The KKT check after the solve allows this many gap tolerances (the solver
#: stops at GAP_RTOL; the BVLS fallback's Cholesky form loses a few digits).
KKT_FACTOR = 10.0
#: Newton steps allowed in force control.
MAX_NEWTON = 60


@functools.lru_cache(maxsize=1)
def _blas_controller():
    try:
        from threadpoolctl import ThreadpoolController
    except ImportError:  # optional: without it BLAS keeps its default threads
        return None
    return ThreadpoolController()


def one_blas_thread():
    """Context limiting BLAS to one thread (threadpoolctl, optional).

    The active-set solves are many small dense factorisations, where BLAS
    threads only synchronise: measured 9 ms vs 140 ms per force-controlled
    solve (31x31 sphere, 2 busy cores; performance.md saw 15x in the HB stage).
    """
    ctl = _blas_controller()
    return contextlib.nullcontext() if ctl is None else ctl.limit(limits=1, user_api="blas")


def _single_threaded(func):
    @functools.wraps(func)
    def wrapper(*args, **kwargs):
        with one_blas_thread():
            return func(*args, **kwargs)
    return wrapper


@dataclass
class NormalSolution:
    """One solved normal contact state.

    Attributes
    ----------
    f : ndarray (n,)      nodal compressive forces of the modelled part [N]
    g : ndarray (n,)      gaps [m]
    q : ndarray (r,)      rigid DOFs: approach [m] (and rotation [rad])
    active : ndarray (n,) bool, nodes in contact
    iterations : int      active-set iterations (summed over Newton steps)
    newton : int          force-control Newton steps (0 in displacement control)
    """

    f: np.ndarray
    g: np.ndarray
    q: np.ndarray
    active: np.ndarray
    iterations: int
    newton: int = 0


def _solve_sub(C, rhs, P):
    """Solution s (n,) of C_PP s_P = rhs_P, zero off P."""
    s = np.zeros(rhs.size)
    if P.any():
        s[P] = sla.solve(C[np.ix_(P, P)], rhs[P], assume_a="pos", check_finite=False)
    return s


def lcp(C: np.ndarray, b: np.ndarray, P0: np.ndarray | None = None, max_iter: int | None = None):
    """Solve g = C f + b >= 0, f >= 0, f g = 0 for SPD C (the QP of the module docstring).

    Parameters
    ----------
    C : ndarray (n, n) SPD; b : ndarray (n,) the effective gap h - R_q q [m]
    P0 : ndarray (n,) bool, optional, a guess of the contact set (warm start;
        default: the penetrating nodes b < 0)
    max_iter : int, optional
        Iteration cap; when given, reaching it raises RuntimeError. By default
        (3 n + 10 iterations) the bounded-QP module's BVLS fallback takes over.

    Returns
    -------
    f : ndarray (n,); active : ndarray (n,) bool (f > 0); iterations : int

    Raises
    ------
    RuntimeError
        If the iteration limit is reached, or the result fails the KKT check.
    """
    n = b.size
    tol = GAP_RTOL * max(np.max(np.abs(b)), 1e-300)
    P = (b < 0) if P0 is None else np.asarray(P0, bool)
    # start (thesis A.1.4-A.1.5): close the gap on the guessed set, drop tension
    f0 = np.maximum(_solve_sub(C, -b, P), 0.0)
    lo, hi = np.zeros(n), np.full(n, np.inf)
    res = qp.solve(C, -b, lo, hi, f0, gtol=tol, max_iter=3 * n + 10 if max_iter is None else max_iter,
                   fallback=max_iter is None, name="normal contact active set")
    qp.check_kkt(res.x, res.g, lo, hi, res.free, xtol=0.0, gtol=KKT_FACTOR * tol,
                 name="normal contact", x_unit="N", g_unit="m")
    return res.x, res.free, res.iterations + 1


@_single_threaded
def solve_displacement(cc: CondensedContact, q, P0=None) -> NormalSolution:
    """Contact state for imposed rigid DOFs q (approach [m] and, flat face, rotation [rad])."""
    q = np.atleast_1d(np.asarray(q, float))
    q = np.concatenate([q, np.zeros(cc.rigid.shape[1] - q.size)])
    b = cc.grid.h - cc.rigid @ q
    f, P, it = lcp(cc.Czz, b, P0)
    return NormalSolution(f=f, g=cc.Czz @ f + b, q=q, active=P, iterations=it)


@_single_threaded
def tangent(cc: CondensedContact, active: np.ndarray) -> np.ndarray:
    """Exact d(resultants)/dq for a fixed active set, shape (r, r).

    Resultants are the full-model force sum(m f) and (flat face) moment
    sum(m f x); f_P = C_PP^-1 (R_q q - h)_P is linear in q for a fixed set.
    """
    R = cc.rigid[active]
    if not active.any():
        return np.zeros((cc.rigid.shape[1],) * 2)
    X = sla.solve(cc.Czz[np.ix_(active, active)], R, assume_a="pos")
    W = (cc.grid.mult[:, None] * cc.rigid)[active]
    return W.T @ X


def resultants(cc: CondensedContact, f: np.ndarray) -> np.ndarray:
    """Full-model force [N] (and moment about y [N m] if r = 2)."""
    return (cc.grid.mult * f) @ cc.rigid


@_single_threaded
def solve_force(cc: CondensedContact, force: float, eccentricity: float | None = None) -> NormalSolution:
    """Contact state for a target full-model force [N] (flat face: and eccentricity [m]).

    Newton on the rigid DOFs with the exact tangent of the current active set
    (piecewise linear resultants, so it ends exactly once the set settles),
    bracketed by bisection on the approach when there is one rigid DOF.
    """
    if not (np.isfinite(force) and force > 0):
        raise ValueError(f"force must be positive, got {force!r}")
    r = cc.rigid.shape[1]
    target = np.array([force] if r == 1 else [force, force * (eccentricity or 0.0)])
    h0 = cc.grid.h.min()
    # one node carrying all the force closes at least as much as the true contact
    q = np.zeros(r)
    q[0] = h0 + np.max(np.diag(cc.Czz)) * force / cc.grid.mult.max()
    lo, hi, its, sol = h0, None, 0, None
    for k in range(1, MAX_NEWTON + 1):
        sol = solve_displacement(cc, q, None if sol is None else sol.active)
        its += sol.iterations
        res = resultants(cc, sol.f)[:r]
        err = target - res
        if np.all(np.abs(err) <= FORCE_RTOL * force * np.array([1.0, _arm(cc)][:r])):
            sol.iterations, sol.newton = its, k
            return sol
        if r == 1:  # F(delta) is increasing: keep a bracket [lo, hi] of the root
            lo, hi = (q[0], hi) if err[0] > 0 else (lo, q[0])
        if sol.active.any():
            q = q + np.linalg.lstsq(tangent(cc, sol.active), err, rcond=None)[0]
        else:  # no contact yet: double the closing
            q[0] = 2 * q[0] - h0
        if r == 1 and not lo < q[0] < (np.inf if hi is None else hi):
            q[0] = 0.5 * (lo + hi) if hi is not None else 2 * lo - h0
    raise RuntimeError(f"force control did not converge in {MAX_NEWTON} Newton steps "
                       f"(target {target}, reached {res})")


def _arm(cc: CondensedContact) -> float:
    """Moment scale [m] for the moment tolerance: the half-width of the grid."""
    return max(np.max(np.abs(cc.grid.x)), 1e-300)
