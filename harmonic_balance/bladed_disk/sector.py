"""Cyclic sector of a tuned bladed disk with one underplatform damper per sector.

Sector DOFs ``q`` (n_dof = n + 3): the blade's n reduced DOFs (:mod:`.blade`; UPD-24:
u_r rim tangential, u_p platform tangential, v_p platform radial, u_a airfoil
first-bending modal DOF), then x_d, y_d, theta_d of damper j (between blade j and
blade j+1). The contact kinematics also use blade j+1's ``right`` platform point
(u', v'), so the *extended* vector is ``q_ext = [q, u', v']`` (n + 5 entries; n + 6
with axial platform DOFs, below).

Cyclic symmetry (symbols in :mod:`config`): blade j+1's harmonic-h complex amplitude
is exp(i h phi) times blade j's, so per harmonic ``q_ext = S(h phi) q`` with
``S(psi)`` (n + 5, n + 3) the identity on q and exp(i psi) on the neighbour's platform
rows. The blade's structure is K(psi) = K + K_next e^(i psi) + K_next^T e^(-i psi)
(:mod:`.blade`, (B1); UPD-24: k_g + 2 k_c (1 - cos psi) on u_r).

Contact kinematics (small rotation, rigid damper): the damper point at r from G
moves by (x_d - theta_d r_y, y_d + theta_d r_x); its displacement relative to the
platform point it touches (blade j's ``left``, blade j+1's ``right``) is Delta;
penetration p = -n . Delta, slip s = t . Delta. ``Q`` (2 n_c, n + 5) stacks the rows
of p and s per contact point (rows 2c, 2c + 1), so the stuck contact stiffness is
``S^H Q^T diag(k) Q S`` and a contact force pair (N, f_t) enters the internal force as
``Q^T [N, f_t]`` (virtual work of V = k_n p^2 / 2 + k_t (s - z)^2 / 2).

A blade whose platform points carry an axial DOF w (``left = [u, v, w]``,
:mod:`.blade`) adds the axial slip s_a = -w of the touched platform point (the damper
is held axially: no axial DOF of its own): three rows per point (p, s, s_a; rows 3c ..
3c + 2, stiffness k_n, k_t, k_t), ``q_ext = [q, u', v', w']`` and each contact slips in
two directions (:class:`~harmonic_balance.contact.ContactElement` with two tangents).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .config import UPDConfig

#: Names of the damper's DOFs (after the blade's).
DAMPER_DOFS = ("x_d", "y_d", "theta_d")


@dataclass
class Sector:
    """Linear matrices and contact kinematics of one sector.

    Attributes
    ----------
    cfg : UPDConfig
    blade : Blade              the blade's reduced matrices and named DOFs
    n_blade, n_dof : int       n and n + 3
    dof_names : tuple of str (n_dof,)
    y_d, forced, response : int  indices of y_d, of the EO force and of the output DOF
    M : (n_dof, n_dof) array   mass [kg, kg m^2]
    points : list of ContactPoint
    Q : (r n_c, n_dof + r) array  rows of penetration p and slip s (and the axial slip
        s_a) per contact point, r = 2 (3 with axial platform DOFs)
    k : (r n_c,) array        stiffness of each row (k_n, k_t[, k_t] per point) [N/m]
    rows_per_point : int      r
    """

    cfg: UPDConfig

    def __post_init__(self):
        d = self.cfg.data["damper"]
        self.blade = b = self.cfg.blade()
        n = self.n_blade = b.n
        self.n_dof = n + 3
        self.dof_names = tuple(b.dofs) + DAMPER_DOFS
        self.y_d, self.forced, self.response = n + 1, b.forced, b.response
        self.M = np.zeros((self.n_dof, self.n_dof))
        self.M[:n, :n] = b.M
        self.M[n:, n:] = np.diag([d["m_d"], d["m_d"], d["I_d"]])
        self.points = self.cfg.contact_points()
        r = self.rows_per_point = len(b.left)   # 2, or 3 with the axial DOF w
        rows, k = [], []
        for c in self.points:
            J = np.zeros((r, n + 3 + r))  # Delta = J q_ext (axial row: the damper is held)
            J[:2, n:n + 2] = np.eye(2)
            J[:2, n + 2] = (-c.r[1], c.r[0])
            cols = tuple(range(n + 3, n + 3 + r)) if c.neighbour else b.left
            for a in range(r):
                J[a, cols[a]] -= 1.0
            rows += [-c.n @ J[:2], c.t @ J[:2]] + ([J[2]] if r == 3 else [])
            k += [c.kn, c.kt] + ([c.kt] if r == 3 else [])
        self.Q = np.array(rows)
        self.k = np.array(k, dtype=float)

    @property
    def n_contacts(self) -> int:
        return len(self.points)

    @property
    def beta(self) -> float:
        return float(self.cfg["blade.beta"])

    @property
    def beta_c(self) -> float:
        return float(self.cfg["damper.beta_c"])

    def _pad(self, A: np.ndarray) -> np.ndarray:
        out = np.zeros((self.n_dof, self.n_dof), dtype=A.dtype)
        out[:self.n_blade, :self.n_blade] = A
        return out

    def K_struct(self, psi: float) -> np.ndarray:
        """Structural stiffness (n_dof, n_dof) [N/m] at phase psi between neighbours (no
        contacts): the blade's K(psi) of (B1); complex Hermitian for a non-symmetric K_next."""
        return self._pad(self.blade.stiffness(psi))

    def C_struct(self, psi: float) -> np.ndarray:
        """Structural damping (n_dof, n_dof) [N s/m]: the blade's C(psi) (beta K(psi) by default)."""
        return self._pad(self.blade.damping(psi, self.beta))

    def S(self, psi: float) -> np.ndarray:
        """Extension (n_dof + r, n_dof) complex: q_ext = S q for phase psi of blade j+1."""
        r = self.rows_per_point
        S = np.zeros((self.n_dof + r, self.n_dof), dtype=complex)
        S[:self.n_dof, :self.n_dof] = np.eye(self.n_dof)
        for a in range(r):
            S[self.n_dof + a, self.blade.right[a]] = np.exp(1j * psi)
        return S

    def K_contact(self, psi: float, normal_only: bool = False) -> np.ndarray:
        """Stuck contact stiffness (n_dof, n_dof) complex Hermitian at phase psi [N/m]
        (only the normal springs with ``normal_only``)."""
        QS = self.Q @ self.S(psi)
        k = self.k.copy()
        if normal_only:  # keep the first row (p) of each point
            k[np.arange(k.size) % self.rows_per_point != 0] = 0.0
        return QS.conj().T @ (k[:, None] * QS)

    def matrices(self, psi: float, damper: str):
        """(M, K, C) at phase psi for ``damper`` = 'free' (removed, blade DOFs only),
        'stuck' (contacts stuck) or 'sliding' (mu = 0: normal springs only).

        C = C_struct + beta_c K_contact (the contact dashpots act on both
        directions in every state, so 'sliding' keeps the tangential ones).
        """
        if damper == "free":
            b = self.blade
            return b.M, b.stiffness(psi), b.damping(psi, self.beta)
        if damper not in ("stuck", "sliding"):
            raise ValueError(f"damper must be 'free', 'stuck' or 'sliding', got {damper!r}")
        Kc = self.K_contact(psi)
        Kk = Kc if damper == "stuck" else self.K_contact(psi, normal_only=True)
        return self.M, self.K_struct(psi) + Kk, self.C_struct(psi) + self.beta_c * Kc

    def forcing(self, f0: float, damper: str = "stuck") -> np.ndarray:
        """Complex amplitude of the EO force on blade j (F0 on the forced DOF),
        shape (n_dof,) or (n,) for the free blade."""
        f = np.zeros(self.n_blade if damper == "free" else self.n_dof, dtype=complex)
        f[self.forced] = f0
        return f


def natural_frequencies(sector: Sector, nd: int, damper: str) -> np.ndarray:
    """Undamped natural frequencies [Hz] at nodal diameter nd, ascending.

    The complex Hermitian eigenproblem K(phi) v = w^2 M v with phi = 2 pi nd / N_b.
    """
    import scipy.linalg as sla  # here: the forced response never loads it

    M, K, _ = sector.matrices(2.0 * np.pi * nd / sector.cfg.blades, damper)
    w2 = sla.eigh(K, M, eigvals_only=True)
    return np.sqrt(np.clip(w2, 0.0, None)) / (2.0 * np.pi)


def modes_table(sector: Sector) -> dict:
    """Free and stuck natural frequencies [Hz] for every nodal diameter 0..N_b/2."""
    nds = list(range(sector.cfg.blades // 2 + 1))
    return {"nodal_diameter": nds,
            "free_hz": [natural_frequencies(sector, nd, "free").tolist() for nd in nds],
            "stuck_hz": [natural_frequencies(sector, nd, "stuck").tolist() for nd in nds]}


def linear_response(sector: Sector, omegas, damper: str, f0: float | None = None) -> np.ndarray:
    """Complex first-harmonic amplitudes (n_omega, n_dof) of the linear limit, direct solve.

    (K(phi) + i omega C(phi) - omega^2 M) U = F, phi the EO interblade phase.
    """
    f0 = sector.cfg.f0 if f0 is None else f0
    M, K, C = sector.matrices(sector.cfg.phi, damper)
    F = sector.forcing(f0, damper)
    return np.array([np.linalg.solve(K + 1j * w * C - w * w * M, F) for w in np.atleast_1d(omegas)])


def modal_response(sector: Sector, omegas, damper: str, f0: float | None = None) -> np.ndarray:
    """The same amplitudes by complex modal superposition of the first-order system.

    State z = [u, u']: A z' = B z + [F, 0] with A = [[C, M], [M, 0]], B = [[-K, 0], [0, M]];
    A^-1 B = V diag(lambda) V^-1 and z = V (i omega - lambda)^-1 V^-1 A^-1 [F, 0].
    Independent of :func:`linear_response` (one eigendecomposition, no frequency solve).
    """
    f0 = sector.cfg.f0 if f0 is None else f0
    M, K, C = sector.matrices(sector.cfg.phi, damper)
    n = M.shape[0]
    Z = np.zeros_like(M, dtype=complex)
    A = np.block([[C, M], [M, Z]])
    B = np.block([[-K, Z], [Z, M]])
    lam, V = np.linalg.eig(np.linalg.solve(A, B))  # LAPACK geev, without scipy's import
    F = np.concatenate([sector.forcing(f0, damper), np.zeros(n)])
    g = np.linalg.solve(V, np.linalg.solve(A, F))
    return np.array([(V @ (g / (1j * w - lam)))[:n] for w in np.atleast_1d(omegas)])


def peak_of(f_fun, lo: float, hi: float, n: int = 400) -> tuple[float, float]:
    """Frequency [rad/s] and value of the maximum of a scalar f_fun(omega) on [lo, hi].

    Grid, then Brent's bounded search in the best grid cell.
    """
    from scipy.optimize import minimize_scalar

    grid = np.linspace(lo, hi, n)
    vals = np.array([f_fun(w) for w in grid])
    i = int(np.argmax(vals))
    a, b = grid[max(i - 1, 0)], grid[min(i + 1, n - 1)]
    res = minimize_scalar(lambda w: -f_fun(w), bounds=(a, b), method="bounded",
                          options={"xatol": 1e-10 * hi})
    return float(res.x), float(-res.fun)
