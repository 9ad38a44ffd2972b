"""Contact element: penalty normal spring with lift-off and friction that follows N.

Local displacements (from :meth:`.kinematics.Kinematics.contact`): ``q = [s, p]``,
the slip ``s = t . Delta`` and the penetration ``p = -n . Delta`` of a contact point
(Delta = body 1 minus body 2, n from body 2 into body 1), or with two tangents
``q = [s_x, s_y, p]`` (the slip in the contact plane: the 2D element of the C core,
``iwan2d.h``, each slider with a circular slip limit). Local forces ``f = [f_t, N]``
(``[f_x, f_y, N]``; conjugate to q; the internal force on body 1 is ``f_t t - N n``)::

    N(theta)   = k_n max(p_0 + p(theta), 0)                              (C1)
    f_t(theta) = Iwan/Jenkins element at slip s - s_0, slip limits x N/N_ref   (C2)
    + dashpots beta_c k_t ds/dt and beta_c k_n dp/dt (linear, always on)  (C3)

p_0 [m] is a static penetration (preload offset: the contact at x = 0 already
carries ``k_n p_0``); with the zeroth harmonic retained the static loads may instead
come from the same solve (e.g. a centrifugal load in harmonic 0). ``N <= 0`` is
lift-off: f_t = 0, the sliders are released and follow the slip; at re-contact the
element restarts virgin from the slip there (C core, ``iwan.h``).

Friction with N varying in time (C2) is evaluated by the C core's periodic path
(``IwanElement.periodic_jac`` with N and its basis EN): periods are marched until the
element's state recurs (closure to ``tol`` of the force range, ``max_periods`` at
most, else ``IwanNotConvergedError``); with N constant over the period the loop is
exact in one pass. It returns dF/dU_s and dF/dU_p exactly, including the
dependence of each sticking slider on N where it stuck and of the re-contact point,
either as the rows of the samples in contact or as sparse terms in the samples (a
diagonal plus the few samples where sliders stuck: ``periodic_jac_terms``), whose
projection onto the harmonics takes one FFT (``FourierBasis.project_terms``) instead
of a product over the samples; :data:`TERMS_MIN_WORK` chooses the cheaper.
With two tangents the 2D loop (``IwanElement2D.periodic_jac``: each slider marched on
its own from the same start convention; on a line it is the 1D loop) gives
d(f_x, f_y)/d(U_sx, U_sy, U_p) exactly, by sensitivities carried through the march.
The C core gets the *unclamped* ``k_n (p_0 + p)``, linear in the harmonics
(EN = k_n E): it treats N <= 0 as lift-off and locates re-contact on the straight
path between samples; (C1) itself is clamped.

Starting (prestress) state of the sliders
-----------------------------------------
``s_0`` [m] is the slip at the prestress state, e.g. the frictionless (mu = 0) static
solution (tmdsimpy's convention; :func:`frictionless_statics` computes it): there the
sliders are virgin (tangential force zero). A periodic loop is then placed by the C
core's convention (``iwan_periodic``): starting from that virgin state, each slider is
moved by the least amount that keeps it within its slip limits over the loop. So a
contact that stays stuck with ``|s - s_0|`` below the slip radii has the defined mean
force ``k_t (mean(s) - s_0)``; a slider that slips in every cycle forgets s_0. With
two tangents s_0 is a 2-vector; the loop starts virgin at s_0 and moves straight to the
first sample before the periods are marched (``iwan2_periodic_jac``): at constant N on a
line this is the 1D convention; a slider that never slips keeps where the first period
left it.
"""
from __future__ import annotations

import numpy as np

from .aft import FrictionLink
from .forces import ForceElement, LinearElement, LocalForce, viscous_work
from .fourier import FourierBasis
from .kinematics import Kinematics

#: Default closure tolerance of the periodic march with varying N, relative to the
#: force range of the period (the C core's measure).
CLOSURE_TOL = 1e-10
#: Default largest number of periods marched until the loop closes.
MAX_PERIODS = 400
#: Work (n_b^2 n_t multiply-adds) of the product D dF/dU over the samples above which a
#: one-tangent contact's Jacobian is projected from the C core's sparse terms instead
#: (an FFT of the diagonal, a few anchor columns: ~80 us of fixed cost, then about
#: n_t log n_t). Measured per contact evaluation on UPD-24 (CF 120 N, F0 30 N): H 7,
#: n_t 256 (0.06e6): product 100 us, terms 155 us; H 15, n_t 512 (0.49e6): 210 us
#: both; H 17, n_t 1024 (1.25e6): 435-490 us against 270-310 us; H 21 (1.9e6): 600 us
#: against 330 us.
TERMS_MIN_WORK = 1.0e6
#: Condition number above which the static stiffness counts as singular (a floating
#: body): 1e-3 / machine epsilon leaves ~3 significant digits in the solve.
SINGULAR_COND = 1e-3 / np.finfo(float).eps


class ContactElement(ForceElement):
    """Penalty normal spring with lift-off, friction following N, optional dashpots.

    Parameters
    ----------
    kinematics : Kinematics
        Local q = [s, p] (m = 2), [s_x, s_y, p] (m = 3: two tangents) or [p] (m = 1,
        normal only); see :meth:`Kinematics.contact`.
    k_n : float
        Normal penalty stiffness [N/m] (> 0).
    friction : object, optional
        Tangential element with ``periodic_jac``, ``step``, ``initial_state``, ``k``,
        ``k_res``, ``N_ref`` (``fmu_src.element.IwanElement``); its slip strengths
        scale with N / N_ref. Required when m = 2. See :meth:`jenkins`.
    preload : float
        Static penetration p_0 [m] at x = 0 (C1).
    slip_ref : float or array_like, shape (2,)
        Prestress slip s_0 [m] where the sliders are virgin (module docstring); a
        2-vector (or a scalar for both) with two tangents.
    beta_c : float
        Contact damping [s]: dashpots beta_c k_t and beta_c k_n in parallel (C3),
        k_t the friction element's stuck stiffness.
    max_periods, tol : int, float
        Periodic march with varying N (module docstring).
    name : str
    """

    def __init__(self, kinematics: Kinematics, k_n: float, friction=None, *, preload: float = 0.0,
                 slip_ref: float = 0.0, beta_c: float = 0.0, max_periods: int = MAX_PERIODS,
                 tol: float = CLOSURE_TOL, name: str = ""):
        m = kinematics.m
        if m not in (1, 2, 3):
            raise ValueError(f"contact kinematics must give [p], [s, p] or [s_x, s_y, p] (m = 1, 2 "
                             f"or 3), got m = {m}")
        if (m >= 2) != (friction is not None):
            raise ValueError("a contact with slip coordinates (m = 2 or 3) needs a friction element, "
                             "a normal-only contact (m = 1) none")
        for label, v, lo in (("k_n", k_n, 0.0), ("beta_c", beta_c, None)):
            if not np.isfinite(v) or v < 0 or (lo is not None and v <= lo):
                raise ValueError(f"{label} must be finite and {'> 0' if lo is not None else '>= 0'}, "
                                 f"got {v}")
        ref = np.asarray(slip_ref, dtype=float)
        if not (np.isfinite(preload) and np.all(np.isfinite(ref))):
            raise ValueError("preload and slip_ref must be finite")
        if ref.ndim > 1 or (ref.ndim == 1 and (m != 3 or ref.size != 2)):
            raise ValueError(f"slip_ref must be a number{' or 2 numbers' if m == 3 else ''}, "
                             f"got shape {ref.shape}")
        self.kinematics, self.name = kinematics, name
        self.k_n, self.friction = float(k_n), friction
        self.preload, self.beta_c = float(preload), float(beta_c)
        self.slip_ref = np.broadcast_to(ref, (2,)).copy() if m == 3 else float(ref)
        self.friction2d = None
        if m == 3:
            from fmu_src.element2d import IwanElement2D
            self.friction2d = IwanElement2D(friction)
        self.max_periods, self.tol = int(max_periods), float(tol)
        self.k_t = 0.0 if friction is None else float(np.sum(friction.k) + friction.k_res)

    @classmethod
    def jenkins(cls, kinematics: Kinematics, k_n: float, k_t: float, mu: float, **kw):
        """Contact with a Jenkins friction element: spring k_t [N/m], slip force mu N."""
        from fmu_src.element import IwanElement

        if not (np.isfinite(k_t) and np.isfinite(mu)) or k_t <= 0 or mu < 0:
            raise ValueError(f"Jenkins contact needs k_t > 0 and mu >= 0, got k_t={k_t}, mu={mu}")
        return cls(kinematics, k_n, IwanElement.jenkins(k_t, mu), **kw)

    # ------------------------------------------------------------ ForceElement
    def stuck_stiffness(self) -> np.ndarray:
        """diag(k_t, k_n) (diag(k_t, k_t, k_n) with two tangents): in contact and stuck."""
        return np.diag([self.k_t] * (self.m - 1) + [self.k_n])

    def local_damping(self):
        if self.beta_c == 0.0:
            return None
        return self.beta_c * self.stuck_stiffness()

    def static_force(self) -> np.ndarray:
        return np.array([0.0] * (self.m - 1) + [self.k_n * max(self.preload, 0.0)])

    def evaluate(self, U, basis: FourierBasis, omega: float, jac: bool = True) -> LocalForce:
        """AFT of (C1)-(C3) on local harmonics U (n_b, m); exact Jacobian.

        Only F, dF and dF_domega are computed here (what a Newton step needs); the
        sampled q, the friction work and the dashpots' work are filled in when first
        read (:class:`ContactForce`), from the same numbers in the same order as an
        eager evaluation, so they are bit-identical to it.
        """
        nb, m, E, D = basis.nb, self.m, basis.E, basis.D
        U = np.asarray(U, dtype=float).reshape(nb, m)
        pl = E @ U[:, -1]
        f = np.empty((basis.n_t, m))
        p, on, f[:, -1] = normal_law(self.k_n, self.preload, pl)
        dF = np.zeros((nb * m, nb * m)) if jac else None
        if jac:  # rows/cols c * m + j: the (j, k) block is dF[j::m, k::m]
            dF[m - 1::m, m - 1::m] = self._normal_block(basis, on)
        W, s = 0.0, None
        if m == 3:
            s, W = self._evaluate_plane(U, basis, p, f, dF, D)
        elif m == 2:
            s, W = self._evaluate_line(U, basis, p, f, dF)
        F = D @ f
        dw, C = None, self._local_damping_cached()
        if C is not None:
            op = self._damping_operator(basis)
            dw = op @ U.ravel()
            F += omega * dw.reshape(nb, m)
            if jac:
                dF += omega * op
        return ContactForce(F, dF, dw, f, float(W), (C, U, basis, omega), (s, pl))


    def _evaluate_line(self, U, basis: FourierBasis, p, f, dF):
        """Friction of one tangent (m = 2) into f[:, 0] and the blocks of dF (if any).

        The projection D dF/dU of the sampled Jacobian is formed from the C core's
        sparse terms (its diagonal by an FFT, a few anchor columns) when the product
        over the samples in contact would cost more than :data:`TERMS_MIN_WORK`, else
        as that product over the packed rows. dF/dU_p = k_n dF/dN (N = k_n p).
        Returns the sampled slips (n_t,) and the friction work per cycle [J]."""
        E, nb, kn = basis.E, basis.nb, self.k_n
        s = E @ U[:, 0]
        kw = {"N": kn * p, "max_periods": self.max_periods, "tol": self.tol}
        if dF is not None and nb * nb * basis.n_t < TERMS_MIN_WORK:
            Ft, rows, dFs, dFp, W = self.friction.periodic_jac_rows(
                s - self.slip_ref, E, EN=self._cached(basis, "EN"), **kw)
            D = basis.D if rows.size == basis.n_t and (rows[1:] > rows[:-1]).all() else basis.D[:, rows]
            dF[0::2, 0::2], dF[0::2, 1::2] = D @ dFs, D @ dFp
        else:
            Ft, dX, dN, row, col, cX, cN, W = self.friction.periodic_jac_terms(
                s - self.slip_ref, with_N=dF is not None, **kw)
            if dF is not None:
                dF[0::2, 0::2], dF[0::2, 1::2] = basis.project_terms(
                    np.stack([dX, kn * dN]), row, col, np.stack([cX, kn * cN]))
        f[:, 0] = Ft
        return s, W

    def _evaluate_plane(self, U, basis: FourierBasis, p, f, dF, D):
        """Friction of two tangents (m = 3) into f[:, :2] and the blocks of dF (if any).

        Returns the sampled slips (n_t, 2) and the friction work per cycle [J]."""
        E = basis.E
        s = np.column_stack([E @ U[:, 0], E @ U[:, 1]])
        res = self.friction2d.periodic_jac(s[:, 0] - self.slip_ref[0], s[:, 1] - self.slip_ref[1],
                                           E if dF is not None else None, N=self.k_n * p,
                                           EN=self._cached(basis, "EN"), max_periods=self.max_periods,
                                           tol=self.tol)
        f[:, :2] = res.F
        if dF is not None:  # dF[j::3, k::3]: force j (x, y) against coordinate k (x, y, p)
            for j in range(2):
                for k in range(3):
                    dF[j::3, k::3] = D @ res.dF[:, j, k, :]
        return s, res.W_cycle

    def _cached(self, basis: FourierBasis, what: str, on=None) -> np.ndarray:
        """Per-basis constants, rebuilt when k_n or the basis change: ``EN`` = k_n E
        (n_t, n_b) and ``Knn`` = D diag(k_n) E (n_b, n_b), the normal block in full
        contact. Computed by the same expressions as the uncached path (bit-identical)."""
        key = (basis.harmonics, basis.n_t, self.k_n)
        cache = getattr(self, "_basis_cache", None)
        if cache is None or cache[0] != key:
            cache = self._basis_cache = (key, {})
        if what not in cache[1]:
            cache[1][what] = (self.k_n * basis.E if what == "EN"
                              else (basis.D * (self.k_n * on)) @ basis.E)
        return cache[1][what]

    def _normal_block(self, basis: FourierBasis, on: np.ndarray) -> np.ndarray:
        """dN/dU_p harmonics D diag(k_n on) E (n_b, n_b); cached when in contact throughout."""
        if on.all():
            return self._cached(basis, "Knn", on)
        return (basis.D * (self.k_n * on)) @ basis.E

    def _local_damping_cached(self):
        """local_damping(), rebuilt only when beta_c, k_t or k_n change."""
        key = (self.beta_c, self.k_t, self.k_n, self.m)
        if getattr(self, "_C", (None,))[0] != key:
            self._C = (key, self.local_damping())
        return self._C[1]

    def _damping_operator(self, basis: FourierBasis) -> np.ndarray:
        """D_theta (x) C_local (n_b m, n_b m), cached per basis."""
        key = (basis.harmonics, self.beta_c, self.k_t, self.k_n)
        if getattr(self, "_dop", (None,))[0] != key:
            self._dop = (key, np.kron(basis.dtheta, self.local_damping()))
        return self._dop[1]

    def stepper(self):
        """Time-domain law: one C-element step per call at N = k_n (p_0 + p)."""
        el, kn, p0, s0, m = self.friction, self.k_n, self.preload, self.slip_ref, self.m
        el = self.friction2d if m == 3 else el
        state = None if el is None else el.initial_state(kn * p0 if p0 > 0 else None)

        class _Contact:
            def force(self, q):
                pen = p0 + q[-1]
                N = kn * max(pen, 0.0)
                if m == 1:
                    return np.array([N])
                if m == 3:
                    return np.append(el.step(state, (q[0] - s0[0], q[1] - s0[1]), kn * pen).F, N)
                return np.array([el.step(state, q[0] - s0, kn * pen).F, N])

            def dissipated(self) -> float:
                """Cumulative friction energy [J] of the carried state."""
                return 0.0 if state is None else state.W

        return _Contact()

    def batch_stepper(self, n: int) -> ContactBatchStepper:
        """``n`` independent virgin histories advanced together (:class:`ContactBatchStepper`)."""
        return ContactBatchStepper(self, n)


def normal_law(k_n, preload, pl):
    """The normal law (C1) on sampled penetrations: p = p_0 + p(theta), in contact where
    p > 0, N = k_n max(p, 0). Arrays broadcast (one contact's samples, or many contacts'
    as (n_e, n_t) with k_n and p_0 as (n_e, 1)).

    Returns
    -------
    p : penetration [m];  on : bool, in contact;  N : normal load [N] (shapes of pl)
    """
    p = preload + pl
    on = p > 0.0
    return p, on, k_n * np.where(on, p, 0.0)


class ContactForce(LocalForce):
    """:class:`~.forces.LocalForce` of a ContactElement with lazy energies and samples.

    ``W_viscous`` (``viscous_work`` of the dashpots), ``W`` (friction loop + dashpots)
    and ``q`` (the sampled [s, p]) are computed on first access and cached: a Newton
    iteration reads only F, dF and dF_domega and skips them.
    """

    def __init__(self, F, dF, dF_domega, f, W_friction, damping, samples):
        self.F, self.dF, self.dF_domega, self.f = F, dF, dF_domega, f
        self._W_friction, self._damping, self._samples = W_friction, damping, samples
        self._Wv = self._q = None

    @property
    def W_viscous(self) -> float:
        if self._Wv is None:
            C, U, basis, omega = self._damping
            self._Wv = 0.0 if C is None else viscous_work(C, U, basis, omega)
        return self._Wv

    @property
    def W(self) -> float:
        return self._W_friction + self.W_viscous

    @property
    def q(self) -> np.ndarray:
        if self._q is None:
            s, pl = self._samples
            s = None if s is None else s.reshape(pl.size, -1)
            self._q = np.empty((pl.size, 1 if s is None else 1 + s.shape[1]))
            self._q[:, -1] = pl
            if s is not None:
                self._q[:, :-1] = s
        return self._q


class ContactBatchStepper:
    """``n`` independent time histories of one ContactElement, one C call per step.

    For vectorised time integration (many frequencies or variants marched together):
    ``force(q)`` advances history i to the local displacement ``q[i]`` exactly as
    :meth:`ContactElement.stepper` would (the C core's ``iwan_step_batch`` runs the
    same code as ``iwan_step``: the same bits), at ``N = k_n (p_0 + p)``. With two
    tangents (m = 3) each history is a 2D state stepped by ``iwan2_step`` in turn.

    Attributes
    ----------
    n : int                 number of histories
    f : (n, m) array        local forces of the last step [N] (overwritten each call)
    """

    def __init__(self, element: ContactElement, n: int, states=None):
        self.element, self.n = element, int(n)
        el, kn, p0 = element.friction, element.k_n, element.preload
        self.f = np.zeros((self.n, element.m))
        self._st = self._st2 = None
        if element.m == 3:
            el2 = element.friction2d
            self._st2 = states if states is not None else [
                el2.initial_state(kn * p0 if p0 > 0 else None) for _ in range(self.n)]
        elif el is not None:
            if states is None:
                states = el.initial_states(self.n, kn * p0 if p0 > 0 else None)
            self._st = el.batch_stepper(states, N=np.zeros(self.n))

    def force(self, q: np.ndarray) -> np.ndarray:
        """Advance every history to q (n, m); returns the local forces (n, m)."""
        e = self.element
        q = np.asarray(q, dtype=float).reshape(self.n, e.m)
        pen = e.preload + q[:, -1]
        self.f[:, -1] = e.k_n * np.maximum(pen, 0.0)
        if self._st is not None:
            np.subtract(q[:, 0], e.slip_ref, out=self._st.u)
            np.multiply(pen, e.k_n, out=self._st.N)
            self.f[:, 0] = self._st.step()
        if self._st2 is not None:
            for i, st in enumerate(self._st2):
                self.f[i, :2] = e.friction2d.step(st, q[i, :2] - e.slip_ref, e.k_n * pen[i]).F
        return self.f

    def dissipated(self) -> np.ndarray:
        """Cumulative friction energy [J] of each history, shape (n,)."""
        if self._st2 is not None:
            return np.array([st.W for st in self._st2])
        if self._st is None:
            return np.zeros(self.n)
        return self._st.states["w_diss"].copy()

    def keep(self, idx) -> ContactBatchStepper:
        """A stepper continuing only the histories ``idx`` (e.g. those not yet settled)."""
        idx = np.asarray(idx, dtype=int)
        if self._st2 is not None:
            return ContactBatchStepper(self.element, idx.size, [self._st2[i] for i in idx])
        states = None if self._st is None else np.ascontiguousarray(self._st.states[idx])
        return ContactBatchStepper(self.element, idx.size, states)


def _static_parts(model):
    """Linear static stiffness (n, n) and the contacts' h = 0 normal rows, for the statics.

    Returns ``K + sum T K_l Q`` of the linear elements and, per ContactElement,
    (index, element, Q_0 (m, d), q_n (n,), t_n (n,)): its h = 0 kinematics and the
    normal row / column on all DOFs (penetration p = p_0 + q_n . x, force t_n N).
    """
    if model.linear.K is None:
        raise ValueError("frictionless statics needs the stiffness matrix K")
    n = model.n
    Klin, rows = np.array(model.linear.K, dtype=float), []
    for i, el in enumerate(model.elements):
        kin = el.kinematics
        Q = kin.Q if not kin.cyclic else kin.Q + kin.Q_next
        T = kin.T if not kin.cyclic else kin.T + kin.T_next
        if isinstance(el, ContactElement):
            qn, tn = np.zeros(n), np.zeros(n)
            qn[list(kin.dofs)], tn[list(kin.dofs)] = Q[-1], T[:, -1]
            rows.append((i, el, Q, qn, tn))
        elif isinstance(el, LinearElement):
            Klin[np.ix_(kin.dofs, kin.dofs)] += T @ el.K @ Q
        elif not isinstance(el, FrictionLink):
            raise TypeError(f"frictionless statics does not know {type(el).__name__}")
    return Klin, rows


def _solve_checked(A, b):
    """x of A x = b, or ValueError when A's condition number is above :data:`SINGULAR_COND`.

    The condition number is LAPACK's 1-norm estimate (gecon) on the LU the solve uses:
    O(n^2) beyond it, where the 2-norm one by SVD took minutes per active set at ~7800
    unknowns (41 surface nodes per side); the two differ by at most a factor n.
    """
    import warnings

    from scipy.linalg import LinAlgWarning, get_lapack_funcs, lu_factor, lu_solve

    with warnings.catch_warnings():   # an exactly zero pivot: rcond 0 below, refused
        warnings.simplefilter("ignore", LinAlgWarning)
        lu, piv = lu_factor(A, check_finite=False)
    (gecon,) = get_lapack_funcs(("gecon",), (lu,))
    rcond, _ = gecon(lu, np.linalg.norm(A, 1), norm="1")
    if not rcond * SINGULAR_COND >= 1.0:   # (a NaN rcond is refused too)
        raise ValueError("frictionless statics is singular: a body is held by friction only "
                         "or floats (no contact in compression holds it)")
    return lu_solve((lu, piv), b, check_finite=False)


def frictionless_statics(model, apply: bool = False, max_iter: int = 100):
    """Static solution with mu = 0 and the slip at each contact (prestress, tmdsimpy's convention).

    Solves ``K x + sum_c T_c [0, N_c(x)] + sum_l T_l K_l Q_l x = f_0`` (f_0 the model's
    harmonic-0 load; N_c from (C1); friction carries no force, mu = 0; linear elements
    with their K) by an active-set iteration on the piecewise-linear normal law: solve
    with the contacts in the active set, update the set from the penetrations, until it
    repeats. Cyclic kinematics enter with their h = 0 map ``Q + Q_next`` (the
    neighbour's static state is the sector's).

    Parameters
    ----------
    model : Model  (matrix model; force elements: ContactElement, LinearElement, FrictionLink)
    apply : bool   set each contact's ``slip_ref`` to its static slip
    max_iter : int

    Returns
    -------
    x : (n,) array               static displacements [m]
    slip : dict {index: float or (2,) array}   s_0 of each ContactElement with friction
        (index in model.elements; two tangents: the 2-vector)
    """
    Klin, rows = _static_parts(model)
    n = model.n
    f0 = np.real(model.forcing.get(0, np.zeros(n))).astype(float)
    active = np.ones(len(rows), dtype=bool)
    # each contact's rows touch its own DOFs only: the outer product added on those (a full
    # (n, n) one per contact took minutes per iteration with thousands of surface nodes)
    dofs = [np.unique(np.asarray(el.kinematics.dofs)) for _, el, _, _, _ in rows]
    for _ in range(max_iter):
        A, b = Klin.copy(), f0.copy()
        for on, d, (_, el, _, qn, tn) in zip(active, dofs, rows):
            if on:  # N = k_n (p0 + qn . x): stiffness tn k_n qn^T, load -tn k_n p0
                A[np.ix_(d, d)] += el.k_n * np.outer(tn[d], qn[d])
                b -= el.k_n * el.preload * tn
        x = _solve_checked(A, b)
        new = np.array([el.preload + qn @ x > 0.0 for _, el, _, qn, _ in rows], dtype=bool)
        if np.array_equal(new, active):
            break
        active = new
    else:
        raise ValueError(f"frictionless statics: contact set still changing after {max_iter} iterations")
    slip = {}
    for i, el, Q, _, _ in rows:
        if el.m >= 2:
            s = Q[:-1] @ x[list(el.kinematics.dofs)]
            slip[i] = float(s[0]) if el.m == 2 else s
            if apply:
                el.slip_ref = slip[i]
    return x, slip
