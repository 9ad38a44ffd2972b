"""Tangential stick/slip contact solve (thesis Appendix A.2, compliance form).

The normal solution is fixed (decoupled problems, thesis A.2.1: the normal
forces do not change with the tangential load; exact for like materials, whose
Johnson coupling constant beta vanishes). The distant faces are moved by a rigid
tangential displacement ``delta`` [m] along x.

Symbols (SI units; n_c contact nodes, those with a normal force f_i > 0)::

    f      (n_c,) nodal normal forces of the modelled part [N] (fixed)
    mu     friction coefficient [-]
    q      (n_c,) nodal tangential forces [N]: the force the contact exerts on the
           plane (body 2) along +x, and on the curved body along -x
    C      (n_c, n_c) combined tangential compliance Cxx [m/N]
    w      (n_c,) full-model weights mult; T = sum(w q) is the full tangential force
    s      (n_c,) accumulated relative slip of body 1 over body 2 [m]

Kinematics: the surfaces' relative x displacement at node i is
``delta - (C q)_i``, the rigid motion minus the elastic give of both bodies;
it is the accumulated slip, so ``s = delta - C q`` after every step.

Incremental problem (from a state ``s_prev`` to a new ``delta``): find q with

    |q_i| <= mu f_i,
    ds_i = (delta - s_prev_i) - (C q)_i = 0          where |q_i| < mu f_i   (stick)
    ds_i * q_i >= 0, q_i = mu f_i sign(ds_i)          where ds_i != 0       (slip)

(Amontons-Coulomb, thesis eq. A.24, with the friction force opposing the
slip increment). These are exactly the optimality (KKT) conditions of the
convex quadratic programme with box constraints

    min_q  1/2 q^T W C q - q^T W (delta - s_prev)   s.t.  -mu f <= q <= mu f,

W = diag(w) (W C is symmetric by reciprocity), whose gradient is ``-W ds``.
It has one solution (W C is positive definite). Each increment is solved as
one step (the history inside a step is taken as proportional, as in any
incremental plasticity scheme; ``contact_core.tangential_curve`` chooses the
steps).

Solver: the bounded-QP module ``contact_core.qp`` (Bertsekas' projected
Newton method, BVLS fallback). Its Newton step is the thesis's stick-set solve
(A.2.5, eq. A.40) with the slip nodes held at +-mu f (A.34-A.36); exchanging
stick and slip sets by their violations alone (A.2.6) was seen to cycle on the
dense half-space compliances, the projected, Armijo-damped step cannot, and
slip nodes may still return to stick (needed on unloading). It stops at a KKT
point within ``SOLVE_TOL``; every result is checked against Coulomb's law (the
KKT conditions) with ``KKT_TOL`` (RuntimeError otherwise).

Full stick (all |q_i| < mu f_i) is linear: ``q = delta C^-1 1``, so the
initial tangential stiffness is exactly ``k_t = w^T C^-1 1``. Gross slip
(q = mu f at every node) is reached at ``delta_gs = max_i (s_prev_i + (C mu f)_i)``.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy import linalg

from . import qp

#: Relative tolerance of the KKT check of every solution: force bounds
#: relative to mu max(f), stick slip increments relative to the displacement
#: scale (C mu f). Round-off of a dense solve is ~1e-13; 1e-8 leaves room for
#: ill-conditioned FE compliances while still catching any wrong stick/slip set.
KKT_TOL = 1e-8
#: Convergence of the projected Newton iteration: slip increments of stick
#: nodes (and wrong-way slips) below this fraction of the displacement scale.
SOLVE_TOL = 1e-11
#: A force within this fraction of its bound mu f counts as at the bound.
SNAP_TOL = 1e-12
#: Iteration cap of the active-set loop (it typically needs 1-5 warm started).
MAX_ITER = 200
#: A compliance with relative asymmetry of W C above this is rejected.
SYMMETRY_TOL = 1e-6


@dataclass(frozen=True)
class TangentialState:
    """Slip history carried from step to step (arrays over the contact nodes).

    Attributes
    ----------
    delta : float
        Rigid tangential displacement of the last step [m].
    s : ndarray, shape (n_c,)
        Accumulated relative slip [m].
    q : ndarray, shape (n_c,)
        Nodal tangential forces [N] (warm start of the next step).
    """

    delta: float
    s: np.ndarray
    q: np.ndarray


@dataclass(frozen=True)
class TangentialSolution:
    """One solved point (arrays over all n nodes of the grid; zero off contact).

    Attributes
    ----------
    delta : float
        Rigid tangential displacement [m].
    T : float
        Full-model tangential force sum(mult q) [N].
    q, s : ndarray, shape (n,)
        Nodal tangential force [N], accumulated slip [m].
    stick, slip : ndarray of bool, shape (n,)
        Contact nodes in stick / in slip (|q| = mu f); both False off contact.
    stick_fraction : float
        Stick share of the contact area (mult- and area-weighted).
    k_tan : float
        Tangent stiffness dT/d(delta) with the current stick set [N/m].
    iterations : int
        Active-set iterations of this step.
    """

    delta: float
    T: float
    q: np.ndarray
    s: np.ndarray
    stick: np.ndarray
    slip: np.ndarray
    stick_fraction: float
    k_tan: float
    iterations: int
    info: dict = field(default_factory=dict)


class TangentialProblem:
    """The tangential problem of a contact with fixed nodal normal forces.

    Parameters
    ----------
    contact : contact_core.condensed.CondensedContact
        Needs ``Cxx`` (condense with direction ``"x"``).
    f_n : ndarray, shape (n,)
        Nodal normal forces of the normal solution [N], >= 0.
    mu : float
        Friction coefficient, >= 0.
    """

    def __init__(self, contact, f_n, mu: float):
        if contact.Cxx is None:
            raise ValueError("tangential solve needs the tangential compliance Cxx "
                             "(condense with directions including 'x')")
        mu = float(mu)
        if not np.isfinite(mu) or mu < 0:
            raise ValueError(f"friction coefficient mu must be finite and >= 0, got {mu}")
        f_n = np.asarray(f_n, dtype=float)
        if f_n.shape != (contact.n,) or not np.all(np.isfinite(f_n)):
            raise ValueError(f"normal forces must be a finite array of shape ({contact.n},)")
        if np.any(f_n < 0):
            raise ValueError("normal forces must be compressive (>= 0)")
        self.contact, self.mu, self.f_n = contact, mu, f_n
        self.idx = np.flatnonzero(f_n > 0)
        if self.idx.size == 0:
            raise ValueError("no node carries a normal force: nothing to load tangentially")
        w = np.asarray(contact.grid.mult, float)[self.idx]
        C = np.asarray(contact.Cxx, float)[np.ix_(self.idx, self.idx)]
        K = w[:, None] * C
        asym = np.abs(K - K.T).max() / np.abs(K).max()
        if asym > SYMMETRY_TOL:
            raise ValueError(f"weighted tangential compliance is not symmetric (relative "
                             f"asymmetry {asym:.2e}): not a reciprocal elastic model")
        self.w, self.C, self.K = w, C, 0.5 * (K + K.T)
        self.bound = mu * f_n[self.idx]
        self.N = float(np.sum(np.asarray(contact.grid.mult, float) * f_n))
        cho = linalg.cho_factor(self.K)
        self.k_t = float(w @ linalg.cho_solve(cho, w))  # w^T C^-1 1 (module docstring)
        self.u_scale = float(np.max(np.abs(C @ self.bound))) or 1.0

    @property
    def n_c(self) -> int:
        """Number of contact nodes."""
        return int(self.idx.size)

    def initial_state(self) -> TangentialState:
        """The virgin state: no slip, no tangential force."""
        z = np.zeros(self.n_c)
        return TangentialState(0.0, z, z.copy())

    def gross_slip_displacement(self, state: TangentialState, sign: float = 1.0) -> float:
        """Smallest displacement, from ``state`` moving in direction ``sign``, at full slip [m]."""
        if sign > 0:
            return float(np.max(state.s + self.C @ self.bound))
        return float(np.min(state.s - self.C @ self.bound))

    def solve(self, state: TangentialState, delta: float):
        """Solve one increment from ``state`` to the rigid displacement ``delta``.

        Returns
        -------
        (TangentialSolution, TangentialState)
            The solution and the state to carry to the next step.
        """
        delta = float(delta)
        if not np.isfinite(delta):
            raise ValueError(f"tangential displacement must be finite, got {delta}")
        r = delta - state.s
        if self.mu == 0.0:  # frictionless: every node slides freely, q = 0
            q, it, free, cho = np.zeros(self.n_c), 0, np.zeros(self.n_c, bool), None
        else:
            res = qp.solve(self.K, self.w * r, -self.bound, self.bound, state.q,
                           gtol=SOLVE_TOL * self.u_scale * self.w.max(), max_iter=MAX_ITER,
                           name="tangential solve")
            q, it, free, cho = res.x, res.iterations, res.free, res.factor
        # a node reaching its bound to round-off is at the bound: snap it, so
        # the stick/slip split does not depend on the last bit (gross slip)
        at = np.abs(q) >= self.bound * (1.0 - SNAP_TOL)
        q = np.where(at, np.sign(q) * self.bound, q)
        if cho is not None and np.any(at & free):
            cho = None
        free = free & ~at
        ds = r - self.C @ q
        # Coulomb's law as the QP's KKT conditions, in slip units: g = -W ds, W > 0
        qp.check_kkt(q, -ds, -self.bound, self.bound, free, xtol=KKT_TOL * self.bound.max(),
                     gtol=KKT_TOL * self.u_scale, name="tangential solve", x_unit="N", g_unit="m")
        k_tan = _tangent_stiffness(self.K, self.w, free, cho)
        new = TangentialState(delta, state.s + np.where(free, 0.0, ds), q)
        return self._expand(delta, q, new.s, free, k_tan, it), new

    def _expand(self, delta, q_c, s_c, free_c, k_tan, it) -> TangentialSolution:
        n = self.contact.n
        q, s = np.zeros(n), np.zeros(n)
        stick, slip = np.zeros(n, bool), np.zeros(n, bool)
        q[self.idx], s[self.idx] = q_c, s_c
        stick[self.idx], slip[self.idx] = free_c, ~free_c
        weight = np.asarray(self.contact.grid.mult, float) * np.asarray(self.contact.grid.area, float)
        frac = float(weight[stick].sum() / weight[self.idx].sum())
        return TangentialSolution(delta, float(self.w @ q_c), q, s, stick, slip, frac, k_tan, it)


def _tangent_stiffness(K, w, free, cho) -> float:
    """dT/d(delta) with the stick set frozen: w_F^T (C_FF)^-1 1 = w_F^T K_FF^-1 w_F."""
    if cho is None:
        if not free.any():
            return 0.0
        cho = linalg.cho_factor(K[np.ix_(free, free)])
    return float(w[free] @ linalg.cho_solve(cho, w[free]))
