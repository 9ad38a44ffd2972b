"""Nonlinear harmonic balance of one UPD sector under cyclic symmetry.

The sector is a standard :class:`~harmonic_balance.model.Model` solved by the package's
:class:`~harmonic_balance.residual.FullResidual` (harmonics 0..H):

* linear part: M, K_struct(0) = K + K_next + K_next^T, C_struct(0) likewise;
* the blade-to-blade coupling (:mod:`.blade` (B1); UPD-24: the rim springs k_c): a
  cyclic :class:`~harmonic_balance.forces.LinearElement` on the DOFs that K_next or
  C_next touch, q = [u_j, u_(j+1)], local stiffness [[-S, K_next], [K_next^T, -S]]
  with S = (K_next + K_next^T) / 2 (dashpots likewise). Its own part plus the part
  of blade j-1's element give -2 S + K_next e^(i h phi) + K_next^T e^(-i h phi) per
  harmonic, so the structure is K_struct(h phi) with damping C_struct(h phi)
  (UPD-24: q = [u_r, u_r'], k_c [[1, -1], [-1, 1]], the rim spring);
* one :class:`~harmonic_balance.contact.ContactElement` per contact point (penalty
  normal spring with lift-off, the C core's Jenkins element with slip force mu N,
  dashpots beta_c k_n, beta_c k_t), its kinematics from :class:`~.sector.Sector`
  (the flat's points with ``Q_next`` on blade j+1's platform and phase phi);
* forcing: F0 on the harmonic-1 cosine of the forced DOF (u_a), CF on the mean of y_d.

The sliders start at the frictionless (mu = 0) prestress state
(:func:`~harmonic_balance.contact.frictionless_statics`, which sets each contact's
``slip_ref``): a loop that never slips is k_t (s - s_static).

Time samples: n_t is a multiple of N_r = N_b / gcd(N_b, EO), so phi is a whole number
of samples and the neighbour's sampled history equals blade j's shifted exactly.
"""
from __future__ import annotations

import numpy as np

from ..contact import ContactElement, frictionless_statics
from ..forces import LinearElement
from ..fourier import FourierBasis, default_samples
from ..kinematics import Kinematics, phase_operator
from ..linear import LinearModel
from ..model import Model
from ..residual import FullResidual
from .sector import Sector


def sector_basis(sector: Sector, H: int, n_t: int = 0) -> FourierBasis:
    """Basis with harmonics 0..H and n_t a multiple of N_r (exact neighbour samples)."""
    nr = sector.cfg.ring_blades
    n_t = n_t or default_samples(H)
    if n_t % nr:
        n_t = int(np.ceil(n_t / nr)) * nr
    return FourierBasis(tuple(range(H + 1)), n_t)


def neighbour_map(basis: FourierBasis, psi: float) -> np.ndarray:
    """Coefficients (n_b, n_b) of u(theta + psi) from those of u(theta)."""
    return phase_operator(basis, psi)


def contact_elements(sector: Sector, mu: float, offset: int = 0, next_offset: int | None = None):
    """ContactElements of one damper (cylinder line + the flat's two end points).

    Their kinematics are the sector's rows of slip and penetration (``Sector.Q``, the
    only copy of the contact geometry), local order [s, p] ([s, s_a, p] with axial
    platform DOFs: two tangents), restricted to the DOFs they touch (the damper's and
    one platform point's).

    Parameters
    ----------
    sector : Sector
    mu : float
        Friction coefficient of the Jenkins points (points with their own
        ``friction`` element keep it).
    offset : int
        First DOF of the sector (blade j) in the model (n_dof j in a ring).
    next_offset : int or None
        First DOF of blade j+1 in a ring model; None: cyclic sector (blade j+1 through
        ``Q_next`` and the phase phi).
    """
    n, right, r = sector.n_dof, list(sector.blade.right), sector.rows_per_point
    els = []
    for i, c in enumerate(sector.points):
        # local q = [s, p] or [s, s_a, p] (ContactElement order: slips, then penetration)
        rows = sector.Q[[r * i + 1, r * i + 2, r * i] if r == 3 else [2 * i + 1, 2 * i]]
        own, nxt = rows[:, :n], rows[:, n:]  # nxt: blade j+1's right platform point (u, v)
        used = np.flatnonzero(np.any(own != 0.0, axis=0))
        if not c.neighbour:
            kin = Kinematics(offset + used, own[:, used])
        elif next_offset is None:
            used = np.union1d(used, right)
            Qn = np.zeros_like(own)
            Qn[:, right] = nxt
            kin = Kinematics(used, own[:, used], Q_next=Qn[:, used], phase=sector.cfg.phi)
        else:
            dofs = np.r_[offset + used, next_offset + np.array(right)]
            kin = Kinematics(dofs, np.hstack([own[:, used], nxt]))
        if c.friction is None:
            els.append(ContactElement.jenkins(kin, c.kn, c.kt, mu, beta_c=sector.beta_c, name=c.name))
        else:  # the point's own element (e.g. a contact_core virgin curve); mu is in it
            els.append(ContactElement(kin, c.kn, c.friction, beta_c=sector.beta_c, name=c.name))
    return els


def coupling_element(sector: Sector) -> LinearElement | None:
    """Cyclic LinearElement of the blade-to-blade coupling (module docstring); None
    for a blade on a rigid disk (no K_next, no C_next)."""
    b = sector.blade
    K_next, C_next = b.K_next, b.damping_parts(sector.beta)[1]
    parts = [A for A in (K_next, C_next) if A is not None]
    if not parts:
        return None
    used = np.flatnonzero(sum(np.any(A != 0.0, axis=0) | np.any(A != 0.0, axis=1) for A in parts))
    if used.size == 0:
        return None
    d = used.size
    eye, zero = np.eye(d), np.zeros((d, d))

    def local(A):
        if A is None:
            return None
        A = A[np.ix_(used, used)]
        S = 0.5 * (A + A.T)
        return np.block([[-S, A], [A.T, -S]])

    kin = Kinematics(used, np.vstack([eye, zero]), Q_next=np.vstack([zero, eye]),
                     phase=sector.cfg.phi)
    Kl = local(K_next)
    return LinearElement(kin, np.zeros((2 * d, 2 * d)) if Kl is None else Kl, local(C_next),
                         name="coupling")


def sector_model(sector: Sector, cf: float, f0: float, mu: float) -> Model:
    """The cyclic sector as a Model (module docstring)."""
    lin = LinearModel(M=sector.M, C=sector.C_struct(0.0), K=sector.K_struct(0.0))
    coupling = coupling_element(sector)
    f_static, f_eo = np.zeros(sector.n_dof), np.zeros(sector.n_dof, dtype=complex)
    f_static[sector.y_d], f_eo[sector.forced] = cf, f0
    return Model(lin, ([coupling] if coupling else []) + contact_elements(sector, mu),
                 {0: f_static, 1: f_eo}, sector.response)


def loads(cfg, cf=None, f0=None, mu=None) -> tuple[float, float, float]:
    """(CF [N], F0 [N], mu) given or from the config, checked: CF, F0 > 0 and mu >= 0, finite."""
    cf = cfg.cf if cf is None else float(cf)
    f0 = cfg.f0 if f0 is None else float(f0)
    mu = cfg.mu if mu is None else float(mu)
    if not (np.isfinite(cf) and cf > 0 and np.isfinite(f0) and f0 > 0):
        raise ValueError(f"CF and F0 must be finite and > 0, got CF={cf}, F0={f0}")
    if not (np.isfinite(mu) and mu >= 0):
        raise ValueError(f"mu must be finite and >= 0, got {mu}")
    return cf, f0, mu


class SectorHB:
    """HB residual of the UPD sector with its exact Jacobian, and its outputs.

    Parameters
    ----------
    sector : Sector
    H : int            highest harmonic (0..H retained)
    cf, f0 : float     centrifugal load and EO force amplitude [N] (default: config)
    mu : float         friction coefficient (default: config)
    n_t : int          AFT samples (rounded up to a multiple of N_r)
    """

    blades = 1

    def __init__(self, sector: Sector, H: int = 7, cf=None, f0=None, mu=None, n_t: int = 0):
        self.sector, self.H = sector, int(H)
        self.cf, self.f0, self.mu = loads(sector.cfg, cf, f0, mu)
        self.basis = sector_basis(sector, self.H, n_t)
        self.model = self._build_model()
        self.x_static, _ = frictionless_statics(self.model, apply=True)
        self.contacts = [i for i, e in enumerate(self.model.elements) if isinstance(e, ContactElement)]
        self.residual = FullResidual(self.model, self.basis)
        self.nb, self.ndof = self.basis.nb, self.model.n
        self.size = self.residual.size
        self.evaluations = 0

    def _build_model(self) -> Model:
        return sector_model(self.sector, self.cf, self.f0, self.mu)

    def with_harmonics(self, H: int, n_t: int = 0) -> SectorHB:
        """The same sector, contacts and loads with harmonics 0..H (``n_t`` AFT samples)."""
        return SectorHB(self.sector, H, cf=self.cf, f0=self.f0, mu=self.mu, n_t=n_t)

    @property
    def points(self):
        return [self.model.elements[i] for i in self.contacts]

    @property
    def static(self) -> dict:
        """Frictionless prestress: q (n,) [m], N (n_c,) normal loads [N], s (n_c,) slips [m]."""
        N, s = [], []
        for el in self.points:
            kin = el.kinematics
            Q = kin.Q + kin.Q_next if kin.cyclic else kin.Q
            q = Q @ self.x_static[list(kin.dofs)]
            N.append(el.k_n * max(el.preload + q[-1], 0.0))
            s.append(q[0])
        return {"q": self.x_static, "N": np.array(N), "s": np.array(s)}

    def set_f0(self, f0: float) -> None:
        """Change the EO force amplitude (start homotopies) [N]."""
        self.f0 = float(f0)
        self.model.forcing[1] = self._eo_forcing()
        self.residual = FullResidual(self.model, self.basis)

    def _eo_forcing(self) -> np.ndarray:
        f = np.zeros(self.ndof, dtype=complex)
        f[self.sector.forced] = self.f0
        return f

    @property
    def Fext(self) -> np.ndarray:
        return self.residual.Fext.ravel()

    def __call__(self, x: np.ndarray, omega: float, jac: bool = True):
        """R (size,), dR/dx (size, size), dR/domega (size,)."""
        last, self._last_value = getattr(self, "_last_value", None), None
        if not (last is not None and last[1] == omega and np.array_equal(last[0], x)):
            self.evaluations += 1   # the Jacobian after value() at this point is no new one
        return self.residual(x, omega, jac)

    def value(self, x: np.ndarray, omega: float) -> np.ndarray:
        """R (size,) alone (``FullResidual.value``: a line search's trial point)."""
        self.evaluations += 1
        self._last_value = (x.copy(), omega)
        return self.residual.value(x, omega)

    # ------------------------------------------------------------ starts
    def static_guess(self) -> np.ndarray:
        """The prestress state in the mean, no vibration."""
        x = np.zeros((self.nb, self.ndof))
        x[self.basis.index(0)[0]] = self.x_static
        return x.ravel()

    def stuck_guess(self, omega: float) -> np.ndarray:
        """Prestress mean + the linear stuck response at harmonic 1 (a Newton start)."""
        from .sector import linear_response

        x = self.static_guess().reshape(self.nb, self.ndof)
        U = linear_response(self.sector, [omega], "stuck", self.f0)[0]
        ic, isn = self.basis.index(1)
        n = self.sector.n_dof
        for j in range(self.blades):
            Uj = U * np.exp(1j * j * self.sector.cfg.phi)
            x[ic, n * j:n * (j + 1)], x[isn, n * j:n * (j + 1)] = Uj.real, -Uj.imag
        return x.ravel()

    # ------------------------------------------------------------ outputs
    def response(self, x: np.ndarray, dof: int | None = None) -> np.ndarray:
        """Harmonic coefficients (n_b,) of ``dof`` (default: the blade's response DOF)."""
        return x.reshape(self.nb, self.ndof)[:, self.sector.response if dof is None else dof]

    def amplitude_h1(self, x, omega=None) -> float:
        """First-harmonic magnitude of the response DOF (u_a) [m]."""
        return float(self.basis.magnitude(self.response(x), 1))

    def amplitude_max(self, x, omega=None) -> float:
        """max |u(t) - mean| of the response DOF (u_a) over the period [m]."""
        c = self.response(x).copy()
        c[self.basis.index(0)[0]] = 0.0
        return self.basis.peak_abs(c)

    def contact_summary(self, x: np.ndarray, omega: float = 0.0) -> dict:
        """Per contact point: mean and range of N [N], lift-off fraction of the period,
        friction energy per cycle of the sampled loop [J]."""
        res = self.residual.evaluate(x, omega, jac=False)
        lf = [res[i] for i in self.contacts]
        N = np.column_stack([r.f[:, -1] for r in lf])
        return {"names": [e.name for e in self.points],
                "normal_load_mean": N.mean(axis=0).tolist(),
                "normal_load_range": np.ptp(N, axis=0).tolist(),
                "lift_off": (N <= 0.0).mean(axis=0).tolist(),
                "friction_energy": [r.W - r.W_viscous for r in lf]}
