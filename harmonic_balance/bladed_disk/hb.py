"""Nonlinear harmonic balance of one UPD sector under cyclic symmetry.

Unknowns: harmonics X (n_b, 7) of the sector DOFs (ordering of :mod:`..fourier`),
harmonics 0..H. Residual (symbols in :mod:`config`, :mod:`sector`)::

    R = (A0 - omega^2 A2 + omega A1) x + L^T F_c(L x) - F_ext

* A0 = blockdiag_h K_struct(h phi), A2 = blockdiag_h h^2 M,
  A1 = beta K_struct(h phi) on d/dtheta + L^T (d/dtheta (x) beta_c diag(k)) L
  (structural damping and the contact dashpots, linear, always active);
* ``L`` maps x to the harmonics W (n_b, 2 n_c) of every contact point's penetration p
  and slip s: W = Q [X, X_platform of blade j+1], with blade j+1's cos/sin pair of
  harmonic h the rotation of blade j's by h phi (u_(j+1)(theta) = u_j(theta + phi));
  L^T brings the neighbour's force back (rotation by -h phi);
* F_c: AFT per contact point, N = k_n max(p, 0), friction f_t from the C core's
  Jenkins element (slip force mu N, ``IwanElement.periodic_jac`` with the varying N and
  its exact derivatives, dF/dN included); the tangential input is s - s_static, so
  the sliders start at the frictionless prestress state (z = s_static) and a loop
  that never slips is the line k_t (s - s_static) (the C core's periodic convention);
* F_ext: F0 on the cos coefficient of harmonic 1 of u_a, CF on the mean of y_d.

Time samples: n_t is a multiple of N_r = N_b / gcd(N_b, EO), so phi is a whole number
of samples and the neighbour's sampled history equals blade j's shifted exactly.
"""
from __future__ import annotations

import numpy as np

from fmu_src.element import IwanElement

from ..fourier import FourierBasis, default_samples
from .sector import N_DOF, U_A, Y_D, Sector


def sector_basis(sector: Sector, H: int, n_t: int = 0) -> FourierBasis:
    """Basis with harmonics 0..H and n_t a multiple of N_r (exact neighbour samples)."""
    nr = sector.cfg.ring_blades
    n_t = n_t or default_samples(H)
    if n_t % nr:
        n_t = int(np.ceil(n_t / nr)) * nr
    return FourierBasis(tuple(range(H + 1)), n_t)


def prestress(sector: Sector, cf: float) -> dict:
    """Frictionless (mu = 0) static state under CF with every contact closed.

    Solves (K_struct(0) + Q0^T diag(k_n) Q0) q = CF e_yd, Q0 the penetration rows at
    phase 0 (the mean is in phase on all blades). Determinate: the damper has three
    equilibrium equations for three normal loads.

    Returns
    -------
    dict: q (7,) static displacements [m], N (n_c,) normal loads [N], p, s (n_c,)
    penetrations and slips [m].
    """
    Q0 = (sector.Q @ sector.S(0.0)).real
    Qp, Qs = Q0[0::2], Q0[1::2]
    kn = sector.k[0::2]
    K = sector.K_struct(0.0) + Qp.T @ (kn[:, None] * Qp)
    f = np.zeros(N_DOF)
    f[Y_D] = cf
    q = np.linalg.solve(K, f)
    p, s = Qp @ q, Qs @ q
    if cf > 0 and np.any(p <= 0):
        raise ValueError("the frictionless prestress opens a contact: check the geometry "
                         "(normals must press the damper against both platforms)")
    return {"q": q, "N": kn * np.maximum(p, 0.0), "p": p, "s": s}


def neighbour_map(basis: FourierBasis, psi: float) -> np.ndarray:
    """Coefficients (n_b, n_b) of u(theta + psi) from those of u(theta)."""
    P = np.zeros((basis.nb, basis.nb))
    for h in basis.harmonics:
        ic, isn = basis.index(h)
        if isn is None:
            P[ic, ic] = 1.0
            continue
        c, s = np.cos(h * psi), np.sin(h * psi)
        P[ic, ic], P[ic, isn], P[isn, ic], P[isn, isn] = c, s, -s, c
    return P


class SectorHB:
    """Residual of the UPD sector (module docstring) with its exact Jacobian.

    Parameters
    ----------
    sector : Sector
    H : int            highest harmonic (0..H retained)
    cf, f0 : float     centrifugal load and EO force amplitude [N] (default: config)
    mu : float         friction coefficient (default: config)
    n_t : int          AFT samples (rounded up to a multiple of N_r)
    """

    def __init__(self, sector: Sector, H: int = 7, cf=None, f0=None, mu=None, n_t: int = 0):
        cfg = sector.cfg
        self.sector, self.H = sector, int(H)
        self.cf = cfg.cf if cf is None else float(cf)
        self.f0 = cfg.f0 if f0 is None else float(f0)
        self.mu = cfg.mu if mu is None else float(mu)
        if not (np.isfinite(self.cf) and self.cf > 0 and np.isfinite(self.f0) and self.f0 > 0):
            raise ValueError(f"CF and F0 must be finite and > 0, got CF={self.cf}, F0={self.f0}")
        if not (np.isfinite(self.mu) and self.mu >= 0):
            raise ValueError(f"mu must be finite and >= 0, got {self.mu}")
        self.basis = b = sector_basis(sector, self.H, n_t)
        self.static = prestress(sector, self.cf)
        self.nb, self.m = b.nb, 2 * sector.n_contacts
        self.size = self.nb * N_DOF
        self._setup_contacts()
        self._build_operators()
        self.Fext = np.zeros((self.nb, N_DOF))
        self.Fext[b.index(1)[0], U_A] = self.f0
        self.Fext[b.index(0)[0], Y_D] = self.cf
        self.Fext = self.Fext.ravel()
        self.evaluations = 0

    def _setup_contacts(self):
        """Contact points, their C-core elements and static slips (one sector)."""
        self.points = self.sector.points
        self.elements = [IwanElement.jenkins(c.kt, self.mu) for c in self.points]
        self.s_static = self.static["s"]

    def set_f0(self, f0: float) -> None:
        """Change the EO force amplitude (start homotopies) [N]."""
        self.f0 = float(f0)
        F = self.Fext.reshape(self.nb, N_DOF)
        F[self.basis.index(1)[0], U_A] = self.f0

    # ------------------------------------------------------------ operators
    def _build_operators(self):
        s, b, nb, m = self.sector, self.basis, self.nb, self.m
        phi = s.cfg.phi
        P = neighbour_map(b, phi)
        Qown, Qnb = s.Q[:, :N_DOF], s.Q[:, N_DOF:]
        L = np.kron(np.eye(nb), Qown)
        # Neighbour platform columns (u_p', v_p') <- rotated (u_p, v_p) of blade j.
        Lnb = np.kron(P, Qnb)  # (nb m, nb 2) on the platform DOFs of every coefficient
        L4 = L.reshape(nb, m, nb, N_DOF)
        L4[:, :, :, 1:3] += Lnb.reshape(nb, m, nb, 2)
        self.L = L4.reshape(nb * m, nb * N_DOF)
        A0 = np.zeros((nb, N_DOF, nb, N_DOF))
        A1 = np.zeros_like(A0)
        for h in b.harmonics:
            idx = [i for i in b.index(h) if i is not None]
            Kh = s.K_struct(h * phi)
            for i in idx:
                A0[i, :, i, :] = Kh
                for j in idx:
                    A1[i, :, j, :] = b.dtheta[i, j] * s.beta * Kh
        shape = (self.size, self.size)
        self.A0 = A0.reshape(shape)
        self.A2 = np.kron(np.diag(b.order.astype(float) ** 2), s.M)
        self.C_contact = self.L.T @ np.kron(b.dtheta, np.diag(s.beta_c * s.k)) @ self.L
        self.A1 = A1.reshape(shape) + self.C_contact

    def linear_operator(self, omega: float) -> np.ndarray:
        return self.A0 - omega**2 * self.A2 + omega * self.A1

    # ------------------------------------------------------------ contact AFT
    def contact_aft(self, w: np.ndarray, jac: bool = True):
        """Harmonics of the contact forces (N, f_t per point) and d/dW.

        Parameters
        ----------
        w : (n_b m,) harmonics of (p, s) per contact point, coefficient-major

        Returns
        -------
        Fh : (n_b m,);  dF : (n_b m, n_b m) or None;  samples : dict of (n_t, n_c)
        arrays p, s, N, f_t and W (n_c,) friction energy per cycle of the sampled loops.
        """
        b, nb, m = self.basis, self.nb, self.m
        E, D = b.E, b.D
        W = w.reshape(nb, m)
        wt = E @ W  # (n_t, m)
        nc = m // 2
        out = {k: np.empty((b.n_t, nc)) for k in ("p", "s", "N", "f_t")}
        out["W"] = np.empty(nc)
        Fh = np.empty((nb, m))
        dF = np.zeros((nb, m, nb, m)) if jac else None
        for c, (pt, el) in enumerate(zip(self.points, self.elements)):
            p, s = wt[:, 2 * c], wt[:, 2 * c + 1]
            on = (p > 0.0).astype(float)
            N = pt.kn * p * on
            dN = (pt.kn * on)[:, None] * E
            ft, dFs, dFp, Wc = el.periodic_jac(s - self.s_static[c], E, N, dN)
            out["p"][:, c], out["s"][:, c], out["N"][:, c], out["f_t"][:, c] = p, s, N, ft
            out["W"][c] = Wc
            Fh[:, 2 * c], Fh[:, 2 * c + 1] = D @ N, D @ ft
            if jac:
                dF[:, 2 * c, :, 2 * c] = D @ dN
                dF[:, 2 * c + 1, :, 2 * c + 1] = D @ dFs
                dF[:, 2 * c + 1, :, 2 * c] = D @ dFp
        return Fh.ravel(), None if dF is None else dF.reshape(nb * m, nb * m), out

    # ------------------------------------------------------------ residual
    def __call__(self, x: np.ndarray, omega: float, jac: bool = True):
        """R (size,), dR/dx (size, size), dR/domega (size,)."""
        self.evaluations += 1
        A = self.linear_operator(omega)
        Fh, dF, _ = self.contact_aft(self.L @ x, jac)
        R = A @ x + self.L.T @ Fh - self.Fext
        if not jac:
            return R
        return R, A + self.L.T @ dF @ self.L, (-2.0 * omega * self.A2 + self.A1) @ x

    def static_guess(self) -> np.ndarray:
        """The prestress state in the mean, no vibration."""
        x = np.zeros((self.nb, N_DOF))
        x[self.basis.index(0)[0]] = self.static["q"]
        return x.ravel()

    def stuck_guess(self, omega: float) -> np.ndarray:
        """Prestress mean + the linear stuck response at harmonic 1 (a Newton start)."""
        from .sector import linear_response

        x = self.static_guess().reshape(self.nb, N_DOF)
        U = linear_response(self.sector, [omega], "stuck", self.f0)[0]
        ic, isn = self.basis.index(1)
        x[ic], x[isn] = U.real, -U.imag
        return x.ravel()

    # ------------------------------------------------------------ outputs
    def response(self, x: np.ndarray, dof: int = U_A) -> np.ndarray:
        return x.reshape(self.nb, N_DOF)[:, dof]

    def amplitude_h1(self, x, omega=None) -> float:
        """First-harmonic magnitude of u_a [m]."""
        return float(self.basis.magnitude(self.response(x), 1))

    def amplitude_max(self, x, omega=None) -> float:
        """max |u_a(t)| over the period (oscillation about the mean) [m]."""
        c = self.response(x).copy()
        c[self.basis.index(0)[0]] = 0.0
        return self.basis.peak_abs(c)

    def contact_summary(self, x: np.ndarray) -> dict:
        """Per contact point: mean and range of N [N], lift-off fraction of the period."""
        _, _, smp = self.contact_aft(self.L @ x, jac=False)
        N = smp["N"]
        return {"names": [p.name for p in self.points],
                "normal_load_mean": N.mean(axis=0).tolist(),
                "normal_load_range": np.ptp(N, axis=0).tolist(),
                "lift_off": (N <= 0.0).mean(axis=0).tolist(),
                "friction_energy": smp["W"].tolist()}
