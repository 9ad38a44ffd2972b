"""A contact surface condensed onto its rigid inputs: the node problem solved in time.

The surface's node DOFs w are massless (:mod:`.surface`), so for a given motion of the
rigid inputs q(theta) their response is quasi-static: at every instant

    A w + f_c(w) = A R q(theta)                                            (Q1)

(A the bodies' node stiffness, R the rigid map, f_c the node contacts with their
friction history), and the surface acts on the structure only through the
resultants on q::

    f_q(theta) = R^T A (R q - w)                                           (Q2)

This element marches (Q1) over the period's AFT samples with the return-mapping solve
of :class:`~.massless.MasslessContacts` (the time integration's own node solve) and
gives the harmonics of (Q2), so the harmonic balance's unknowns are the structure's
alone and no node's slip is truncated to H harmonics: the node response is exact at
the samples for the given q (a nonlinear element in the sense of the dynamic
Lagrangian frequency-time method's condensation onto the interface, Nacivet, Pierre,
Thouverez & Jezequel, J. Sound Vib. 265, 2003; here with the node law solved by an
incremental return mapping, Simo & Hughes 1998, instead of a Lagrangian
prediction-correction). The harmonic balance's Newton then sees a residual in a few
structure unknowns whose kinks are those of the surface's resultant, not those of
every node's contact and slip.

Periodic state: the march starts from the prestress (the frictionless statics' w,
sliders virgin there, as the node ContactElements' ``slip_ref``), moves straight to
q(0) and runs ``periods`` periods; the last one is the steady loop (a node that slips
in every cycle has forgotten the start; one that never slips keeps where the first
period left it, the C core's convention for a point contact).

Jacobian: dF/dU exact, by the forward sensitivities of the march
(:mod:`.surface_sensitivity`: each committed step's settled set gives dw/dq and the
friction states' sensitivities by the implicit function theorem, carried from step to
step), along the n_b r directions of U in the residual's own march (one history;
the sensitivities cost about what the march does). The forward differences of the whole march
(:meth:`CondensedSurface.jacobian_fd`, 1 + n_b r histories) are kept as its reference.

Cost: every node over ``PERIODS`` periods of node solves per evaluation, plus one
linear solve of the settled set per step for the sensitivities; the blocks' LU factors
are kept by contact state (:class:`~.massless.FactorCache`, one per element, across
evaluations), so a stick phase and the repeated period solve with factors already
made; blocks of 100 DOFs and more are solved by diagonal updates of a few kept inverses
(the node solve's and the sensitivities' operators differ only in the nodes' contact
stiffnesses), and a normal block's sensitivities for the r columns of A R only. A march of
one history makes each step's node solve and sensitivity advance in one C call each
(:mod:`.massless_c`, the same numbers as the numpy path, which :attr:`CondensedSurface.compiled`
= False selects). Measured costs (UPD-24, 5 to 20 nodes per side):
docs/method/contact_surface.md.

Symbols as in :mod:`.surface`; q (r,) the rigid inputs, U (n_b, r) their harmonics.
"""
from __future__ import annotations

import numpy as np

from .forces import ForceElement, LocalForce, viscous_work
from .fourier import FourierBasis
from .massless import MAX_NEWTON, MAX_NEWTON_UNSPLIT, FactorCache, MasslessContacts
from .surface_sensitivity import MarchSensitivity

#: Periods marched; the last is the loop. A node that first slips in period 2 or later
#: (the amplitude grows through the march only at its start) would need more.
PERIODS = 2
#: Forward-difference step of the reference Jacobian (:meth:`CondensedSurface.jacobian_fd`)
#: relative to each input's amplitude. The node solve stops at 1e-7 of the loads
#: (massless.RESIDUAL_RTOL), so a step of 1e-7 differences that tolerance (measured: 20 %
#: off the exact Jacobian in some entries); the march is piecewise linear in U (bilinear
#: where a node re-contacts inside a step), so 1e-4 stays on one piece away from kinks and
#: agrees with the exact Jacobian to ~1e-8 (tests/hb/test_surface_sensitivity.py).
FD_REL = 1e-4
#: Load steps from the prestress to the first sample (the node solve's Newton settles a
#: step within MAX_NEWTON iterations only for moderate changes of the contact set).
RAMP = 8
#: Halvings of a time step whose node solve does not settle in massless.MAX_NEWTON
#: iterations (the load path is the same straight line, in shorter steps); the shortest
#: step may take massless.MAX_NEWTON_UNSPLIT.
MAX_SPLIT = 4


class CondensedSurface(ForceElement):
    """A surface as a force element on its r rigid inputs (module docstring).

    Parameters
    ----------
    surface : harmonic_balance.surface.Surface
        Planar (node contacts with one slip direction).
    kinematics : Kinematics
        Maps the model's DOFs to q (m = r local coordinates, the surface's ``inputs``).
    q_static : ndarray (r,)
        Rigid inputs of the prestress [m, rad].
    w_static : ndarray (n_w,)
        Node displacements of the prestress (frictionless statics) [m].
    slip_ref : ndarray (n,)
        Each node's static slip (its ContactElement's ``slip_ref``) [m].
    damping : ndarray (r, r), optional
        Dashpots on q [N s/m].
    name : str
    """

    def __init__(self, surface, kinematics, q_static, w_static, slip_ref, damping=None,
                 name: str = ""):
        if surface.tangents != ("x",):
            raise ValueError("a condensed surface must be planar (tangents ('x',))")
        self.surface, self.kinematics, self.name = surface, kinematics, name
        n_w = surface.n_w
        self.A = surface.K[:n_w, :n_w]
        self.AR = -surface.K[:n_w, n_w:]          # A R
        self.RtA = self.AR.T
        self.RtAR = surface.K[n_w:, n_w:]
        self.w_static = np.asarray(w_static, float)
        self.q_static = np.asarray(q_static, float)
        self.elements = []
        for el, s0 in zip(surface.elements, slip_ref):
            self.elements.append(type(el)(el.kinematics, el.k_n, el.friction, preload=el.preload,
                                          slip_ref=float(s0), name=el.name))
        self.C = None if damping is None else np.asarray(damping, float)
        # the node solves' and sensitivities' block factors, kept across evaluations: A is
        # fixed and the keys are the contact states, not the motion
        self.factors = FactorCache()

    def stuck_stiffness(self) -> np.ndarray:
        """Condensed stiffness (r, r) on q with every node closed and stuck [N/m]."""
        nodes = MasslessContacts(self.elements, range(self.surface.n_w), 1)
        Kc = nodes.stuck_stiffness()
        return self.RtAR - self.RtA @ np.linalg.solve(self.A + Kc, self.AR)

    def local_damping(self):
        return self.C

    #: Whether a march of one history solves its steps in C (massless_c; the numpy path,
    #: its reference, where False or where the C step does not apply).
    compiled = True

    #: Periods each evaluation marches (:data:`PERIODS`; an instance may set its own to
    #: measure what the first period's transient leaves in the loop).
    periods = PERIODS

    def march(self, q: np.ndarray, periods: int | None = None, dq=None):
        """Resultants f_q (n_h, n_t, r) [N] and the last period's friction work (n_h,) [J] of
        histories q (n_h, n_t, r) [m, rad], each one period of samples (module docstring),
        over ``periods`` periods (default :attr:`periods`).

        With ``dq`` (n_t, r, n_d), the sensitivities of the samples along n_d directions
        (the same for every history), also their resultants' sensitivities df (n_h, n_t,
        r, n_d) by the march's forward sensitivities (:mod:`.surface_sensitivity`).

        Raises
        ------
        RuntimeError
            The node solve found no equilibrium even in a step split MAX_SPLIT times.
        """
        periods = self.periods if periods is None else int(periods)
        n_h, n_t, r = q.shape
        nodes = MasslessContacts(self.elements, range(self.surface.n_w), n_h, self.A != 0.0)
        A = nodes.split(self.A)
        if n_h == 1:
            nodes.factors = self.factors
            if self.compiled:
                nodes.compile(A)
        sens = None if dq is None else MarchSensitivity(nodes, self.A, self.AR, dq.shape[2])
        dq = np.zeros((n_t, r, 0)) if dq is None else dq
        w = np.tile(self.w_static, (n_h, 1))
        f = np.empty_like(q)
        df = None if sens is None else np.empty((n_h, n_t, r, dq.shape[2]))
        q_prev, dq_prev = np.tile(self.q_static, (n_h, 1)), np.zeros_like(dq[0])
        for a in np.linspace(0.0, 1.0, RAMP + 1)[1:-1]:   # from the prestress towards q(0)
            q_a = (1.0 - a) * q_prev + a * q[:, 0]
            dq_a = (1.0 - a) * dq_prev + a * dq[0]
            w = self._step(nodes, A, (q_prev, dq_prev), (q_a, dq_a), w, 0, sens)
            q_prev, dq_prev = q_a, dq_a
        W0 = None
        for p in range(periods):
            if p == periods - 1:
                W0 = nodes.dissipated()
            for k in range(n_t):
                w = self._step(nodes, A, (q_prev, dq_prev), (q[:, k], dq[k]), w, 0, sens)
                q_prev, dq_prev = q[:, k], dq[k]
                f[:, k] = q[:, k] @ self.RtAR.T - w @ self.RtA.T
                if sens is not None and p == periods - 1:
                    df[:, k] = (self.RtAR @ dq[k])[None] - np.einsum("rb,hbd->hrd", self.RtA, sens.dw)
        if sens is None:
            return f, nodes.dissipated() - W0
        return f, nodes.dissipated() - W0, df

    def _step(self, nodes, A, start, end, w, depth, sens=None):
        """Equilibrium (Q1) at q_1 from the committed state at q_0 (``start``, ``end``: (q,
        dq) pairs); halves the step where the node solve does not settle (it commits only a
        settled step) and carries ``sens`` over each committed step."""
        before = None if sens is None else [st.copy() for st in nodes.states]
        # the shortest step gets the iterations of a step that cannot split: a node at a kink
        # of its trial map at the solution leaves Newton converging linearly there, and
        # halving the step does not move the kink
        last = depth >= MAX_SPLIT
        try:
            w1 = nodes.solve(A, end[0] @ self.AR.T, w, MAX_NEWTON_UNSPLIT if last else MAX_NEWTON)
        except RuntimeError:
            if last:
                raise
        else:
            if sens is not None:
                sens.advance(before, w1, end[1])
            return w1
        mid = tuple(0.5 * (x0 + x1) for x0, x1 in zip(start, end))
        w = self._step(nodes, A, start, mid, w, depth + 1, sens)
        return self._step(nodes, A, mid, end, w, depth + 1, sens)

    def evaluate(self, U, basis: FourierBasis, omega: float, jac: bool = True) -> LocalForce:
        """Harmonics of (Q2) for input harmonics U (n_b, r); with ``jac`` their exact dF/dU
        from the same march (module docstring)."""
        nb, r = basis.nb, self.m
        U = np.asarray(U, float).reshape(nb, r)
        dq = self._directions(basis, r) if jac else None
        Fs, f, W, q, dFs = self._resultants(U[None], basis, dq)
        F, dw, Wv = Fs[0], None, 0.0
        dF = None if dFs is None else dFs[0].reshape(nb * r, nb * r)
        if self.C is not None:
            op = np.kron(basis.dtheta, self.C)
            dw = op @ U.ravel()
            F = F + omega * dw.reshape(nb, r)
            Wv = viscous_work(self.C, U, basis, omega)
            if dF is not None:
                dF = dF + omega * op
        return LocalForce(F, dF, dw, W=float(W[0]) + Wv, W_viscous=Wv, q=q[0], f=f[0])

    @staticmethod
    def _directions(basis, r) -> np.ndarray:
        """dq (n_t, r, n_b r): the samples' sensitivity to each harmonic of each input."""
        n_t = basis.E.shape[0]
        return np.einsum("tb,ij->tibj", basis.E, np.eye(r)).reshape(n_t, r, basis.nb * r)

    def _resultants(self, Us, basis, dq=None):
        """Harmonics (n_h, n_b, r) of the resultants of input harmonics Us (n_h, n_b, r), with
        the samples f, the friction work W, the inputs' samples q and, given the samples'
        sensitivities dq (n_t, r, n_d), the harmonics' (n_h, n_b, r, n_d) (else None)."""
        q = np.einsum("tb,hbr->htr", basis.E, Us)
        try:
            out = self.march(q, dq=dq)
        except RuntimeError:
            # no node equilibrium along this motion (e.g. a trial step far off): a
            # non-finite force, which a line search rejects and a Newton start reports
            nan = np.full_like(q, np.nan)
            out = (nan, np.full(q.shape[0], np.nan)) + (() if dq is None else (nan[..., None] + dq[0, 0],))
        Fs = np.einsum("bt,htr->hbr", basis.D, out[0])
        dFs = None if dq is None else np.einsum("bt,htrd->hbrd", basis.D, out[2])
        return Fs, out[0], out[1], q, dFs

    def jacobian_fd(self, U, basis, omega, rel: float = FD_REL) -> np.ndarray:
        """dF/dU (n_b r, n_b r) by forward differences (the base and every column one batched
        march of 1 + n_b r histories): the reference the exact Jacobian is tested against."""
        nb, r = basis.nb, self.m
        cols = nb * r
        Us = np.repeat(U[None], 1 + cols, axis=0)
        h = rel * np.maximum(np.abs(U).max(axis=0), 1e-300)   # (r,)
        for j in range(cols):
            Us[1 + j].flat[j] += h[j % r]
        Fs = self._resultants(Us, basis)[0]
        dF = ((Fs[1:] - Fs[0]).reshape(cols, cols) / np.tile(h, nb)[:, None]).T
        if self.C is not None:
            dF = dF + omega * np.kron(basis.dtheta, self.C)
        return dF
