"""Harmonic-balance residuals R(x, omega) with exact Jacobians.

Full residual (all n DOFs; unknowns X (n_b, n), flattened as in :mod:`fourier`)::

    R = A(omega) X + F_nl(X) - F_ext,
    A(omega) = I (x) K - omega^2 diag(h^2) (x) M + omega D_theta (x) C

where ``D_theta`` is d/dtheta in coefficient space (so omega D_theta X are the velocity
harmonics) and ``(x)`` the Kronecker product. F_nl comes from the AFT (:mod:`aft`);
being rate-independent it does not depend on omega, so
``dR/domega = (-2 omega diag(h^2) (x) M + D_theta (x) C) X``.

Condensed residual (unknowns: the harmonics of the m DOFs the friction links touch,
set J)::

    R = X_J - G_JJ(omega) F_ext - ... = X_J - X_lin,J(omega) + G_JJ(omega) F_nl,J(X_J)

with the receptance G of the linear part per harmonic (:mod:`linear`), so the
unknowns and the cost do not grow with the size of the linear model (modal G).
Both return ``R (N,), dR/dx (N, N), dR/domega (N,)``.
"""
from __future__ import annotations

import numpy as np

from .aft import aft_link
from .fourier import FourierBasis
from .model import Model


class _Residual:
    """Shared AFT assembly over the links, on a set of 'active' DOFs."""

    def __init__(self, model: Model, basis: FourierBasis, dofs):
        self.model, self.basis = model, basis
        self.dofs = np.asarray(dofs, dtype=int)
        self.m = self.dofs.size
        pos = {int(d): i for i, d in enumerate(self.dofs)}
        nb = basis.nb
        # Coefficient-major indices (c * m + local DOF) of each link's two ends.
        self._ends = []
        for link in model.links:
            ia = np.arange(nb) * self.m + pos[link.dof_a]
            ib = None if link.dof_b is None else np.arange(nb) * self.m + pos[link.dof_b]
            self._ends.append((link, ia, ib))
        self.size = nb * self.m
        self.Fext = model.forcing_coeffs(basis)  # (nb, n)
        # Signed incidence B (size, L n_b): column block l maps link l's harmonics
        # to its two ends (+1 at a, -1 at b), so U = B^T x, F_nl = B F_h and
        # dF_nl/dx = B blockdiag(dF_h/dU) B^T: three dense products, no scatter loop.
        L = len(self._ends)
        self._B = np.zeros((self.size, L * nb))
        for l, (_, ia, ib) in enumerate(self._ends):
            self._B[ia, l * nb + np.arange(nb)] = 1.0
            if ib is not None:
                self._B[ib, l * nb + np.arange(nb)] = -1.0

    def nonlinear(self, x: np.ndarray, jac: bool = True):
        """Internal friction forces (size,) on the active DOFs, Jacobian, energies."""
        nb, L = self.basis.nb, len(self._ends)
        U = (self._B.T @ x).reshape(L, nb)
        Fh = np.empty((L, nb))
        J = np.zeros((L * nb, L * nb)) if jac else None
        W = []
        for l, (link, _, _) in enumerate(self._ends):
            Fh[l], Jl, w, _ = aft_link(link, U[l], self.basis)
            W.append(w)
            if jac:
                J[l * nb:(l + 1) * nb, l * nb:(l + 1) * nb] = Jl
        Fnl = self._B @ Fh.ravel()
        return Fnl, (self._B @ J @ self._B.T if jac else None), W

    def link_samples(self, x: np.ndarray):
        """Per link: relative displacement and force over one period, (n_t,) each."""
        out = []
        for link, ia, ib in self._ends:
            U = x[ia] if ib is None else x[ia] - x[ib]
            _, _, w, F = aft_link(link, U, self.basis)
            out.append((self.basis.E @ U, F, w))
        return out


class FullResidual(_Residual):
    """HB residual on all DOFs of a matrix model (see module docstring)."""

    def __init__(self, model: Model, basis: FourierBasis):
        lin = model.linear
        if lin.K is None:
            raise ValueError("the full residual needs M, C, K matrices (use the condensed one)")
        super().__init__(model, basis, np.arange(model.n))
        I = np.eye(basis.nb)
        h2 = np.diag(basis.order.astype(float) ** 2)
        self._K = np.kron(I, lin.K)
        self._M = np.kron(h2, lin.M)
        self._C = np.kron(basis.dtheta, lin.C)
        self._f = self.Fext.ravel()

    def __call__(self, x: np.ndarray, omega: float, jac: bool = True):
        A = self._K - omega**2 * self._M + omega * self._C
        Fnl, dF, _ = self.nonlinear(x, jac)
        R = A @ x + Fnl - self._f
        if not jac:
            return R
        return R, A + dF, (-2.0 * omega * self._M + self._C) @ x

    def linear_guess(self, omega: float) -> np.ndarray:
        """Solution with every link replaced by its stuck spring k_0."""
        A = self._K - omega**2 * self._M + omega * self._C
        return np.linalg.solve(A + _stuck_links(self._ends, self.basis.nb, A.shape[0]), self._f)

    def displacements(self, x: np.ndarray, omega: float) -> np.ndarray:
        """Harmonics of all DOFs (n_b, n)."""
        return x.reshape(self.basis.nb, self.m)


class CondensedResidual(_Residual):
    """HB residual condensed onto the friction DOFs through the receptance."""

    def __init__(self, model: Model, basis: FourierBasis):
        dofs = sorted({d for link in model.links for d in link.dofs})
        if not dofs:
            raise ValueError("the condensed residual needs at least one friction link")
        super().__init__(model, basis, dofs)
        self._cache = (None, None)

    def _real_block(self, rows, cols, omega: float, deriv: bool):
        """Receptance on real coefficient pairs, (n_b len(rows), n_b len(cols)), + d/domega."""
        lin, b = self.model.linear, self.basis
        nr, nc = len(rows), len(cols)
        G = np.zeros((b.nb, nr, b.nb, nc))
        dG = np.zeros_like(G) if deriv else None
        gs, dgs = lin.receptances(np.asarray(b.harmonics) * omega, rows, cols, deriv)
        for k, h in enumerate(b.harmonics):
            ic, isn = b.index(h)
            for out, val in ((G, gs[k]), (dG, None if dgs is None else h * dgs[k])):
                if out is None:
                    continue
                if isn is None:
                    out[ic, :, ic, :] = val.real
                    continue
                # a = Re G f_a + Im G f_b,  b = Re G f_b - Im G f_a  (linear.py)
                out[ic, :, ic, :], out[ic, :, isn, :] = val.real, val.imag
                out[isn, :, ic, :], out[isn, :, isn, :] = -val.imag, val.real
        shape = (b.nb * nr, b.nb * nc)
        return G.reshape(shape), None if dG is None else dG.reshape(shape)

    def _linear_response(self, rows, omega: float, deriv: bool):
        """Response (n_b, len(rows)) of the linear part to F_ext, and d/domega."""
        b, lin = self.basis, self.model.linear
        X = np.zeros((b.nb, len(rows)))
        dX = np.zeros_like(X)
        for h, f in self.model.forcing.items():
            ic, isn = b.index(h)
            U, dU = lin.response(h * omega, rows, f, deriv)
            X[ic] = U.real
            if deriv:
                dX[ic] = h * dU.real
            if isn is not None:
                X[isn] = -U.imag
                if deriv:
                    dX[isn] = -h * dU.imag
        return X, dX

    def _operators(self, omega: float):
        if self._cache[0] != omega:
            G, dG = self._real_block(self.dofs, self.dofs, omega, True)
            X, dX = self._linear_response(self.dofs, omega, True)
            self._cache = (omega, (G, dG, X.ravel(), dX.ravel()))
        return self._cache[1]

    def __call__(self, x: np.ndarray, omega: float, jac: bool = True):
        G, dG, Xl, dXl = self._operators(omega)
        Fnl, dF, _ = self.nonlinear(x, jac)
        R = x - Xl + G @ Fnl
        if not jac:
            return R
        return R, np.eye(self.size) + G @ dF, -dXl + dG @ Fnl

    def linear_guess(self, omega: float) -> np.ndarray:
        """Solution with every link replaced by its stuck spring k_0."""
        G, _, Xl, _ = self._operators(omega)
        Kst = _stuck_links(self._ends, self.basis.nb, self.size)
        return np.linalg.solve(np.eye(self.size) + G @ Kst, Xl)

    def displacements(self, x: np.ndarray, omega: float, rows=None) -> np.ndarray:
        """Harmonics (n_b, len(rows)) of any DOFs, recovered through the receptance."""
        rows = np.arange(self.model.n) if rows is None else np.asarray(rows)
        Fnl, _, _ = self.nonlinear(x, jac=False)
        G, _ = self._real_block(rows, self.dofs, omega, False)
        X, _ = self._linear_response(rows, omega, False)
        return X - (G @ Fnl).reshape(self.basis.nb, len(rows))


def make_residual(model: Model, basis: FourierBasis, condensed: bool | None = None):
    """Pick the residual: condensed when the model is modal-only or larger than the link DOFs."""
    if condensed is None:
        m = len({d for link in model.links for d in link.dofs})
        condensed = model.linear.K is None or (0 < m < model.n)
    return CondensedResidual(model, basis) if condensed else FullResidual(model, basis)


def energy_per_cycle(model: Model, basis: FourierBasis, X: np.ndarray, omega: float) -> dict:
    """Work per cycle [J] of the excitation and the viscous damping, from harmonics X (n_b, n).

    For x = a cos(h theta) + b sin(h theta) over one period 2 pi / omega:
    excitation work  pi h (f_a . b - f_b . a);  viscous  pi h^2 omega (a.C a + b.C b).
    Needs the C matrix (matrix models).
    """
    F = model.forcing_coeffs(basis)
    C = model.linear.C
    w_ext = w_visc = 0.0
    for h in basis.harmonics:
        if h == 0:
            continue
        ic, isn = basis.index(h)
        a, b = X[ic], X[isn]
        w_ext += np.pi * h * (F[ic] @ b - F[isn] @ a)
        if C is not None:
            w_visc += np.pi * h**2 * omega * (a @ C @ a + b @ C @ b)
    return {"W_ext": float(w_ext), "W_visc": float(w_visc) if C is not None else None}


def _stuck_links(ends, nb: int, size: int) -> np.ndarray:
    """Stiffness (size, size) of every link stuck at k0, on its harmonic index blocks.

    ``ends`` holds (link, ia, ib): index arrays (nb,) of the link's two ends in the
    unknown vector (ib None for a link to the ground).
    """
    Kst = np.zeros((size, size))
    J = np.eye(nb)
    for link, ia, ib in ends:
        Kst[np.ix_(ia, ia)] += link.k0 * J
        if ib is not None:
            Kst[np.ix_(ia, ib)] -= link.k0 * J
            Kst[np.ix_(ib, ia)] -= link.k0 * J
            Kst[np.ix_(ib, ib)] += link.k0 * J
    return Kst
