"""The linear part of a model: dynamic stiffness and receptance per harmonic.

Equation of motion (SI: M [kg], C [N s/m], K [N/m], x [m], f [N])::

    M x'' + C x' + K x + f_nl(x) = f_ext(t)

For harmonic h at angular frequency omega (Omega = h omega) the complex dynamic
stiffness is ``Z = K - Omega^2 M + i Omega C`` and the receptance ``G = Z^-1``
(complex amplitudes U = a - i b, see :mod:`fourier`). On the real pair (a, b)::

    [ K - Omega^2 M    Omega C      ] [a]   [f_a]
    [ -Omega C         K - Omega^2 M] [b] = [f_b]

and the receptance acts as ``a = Re G f_a + Im G f_b``, ``b = Re G f_b - Im G f_a``.

Two representations of the receptance:

* modal: mass-normalised modes ``phi`` (n, r), natural frequencies ``w_r`` and modal
  damping ``c_r = 2 zeta_r w_r``: ``G = phi diag(1 / (w_r^2 - Omega^2 + i Omega c_r)) phi^T``.
  Restricted to a few DOFs it costs O(m^2 r), independent of the FE model size.
* direct: a complex solve with Z (used when C is not diagonalised by the modes).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: Relative size of the off-diagonal part of phi^T C phi below which C counts as
#: modal (proportional) damping; round-off of eigh is ~1e-14.
MODAL_DAMPING_TOL = 1e-9
#: Relative asymmetry tolerated in M, C, K (round-off of an assembly).
SYMMETRY_TOL = 1e-10


def _eigh_general(K: np.ndarray, M: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Eigenvalues (n,) ascending and M-orthonormal vectors (n, n) of K phi = lam M phi.

    The reduction LAPACK's sygvd makes (M = L L^T, L^-1 K L^-T v = lam v, phi = L^-T v),
    in numpy: the same numbers to round-off without loading scipy.linalg (a third of a
    second of every ``damper frf``'s start-up on a busy machine). LinAlgError when M is
    not positive definite.
    """
    L = np.linalg.cholesky(M)
    A = np.linalg.solve(L, np.linalg.solve(L, K).T)
    lam, v = np.linalg.eigh(0.5 * (A + A.T))
    return lam, np.linalg.solve(L.T, v)


@dataclass
class LinearModel:
    """Linear structure, as matrices and/or modes.

    Parameters
    ----------
    M, C, K : (n, n) arrays or None
        Mass, damping, stiffness (None for modal-only data).
    phi : (n, r) array or None
        Mass-normalised mode shapes (phi^T M phi = I).
    w_r : (r,) array or None
        Natural angular frequencies [rad/s].
    c_r : (r,) array or None
        Modal damping coefficients 2 zeta_r w_r [1/s].
    """

    M: np.ndarray | None = None
    C: np.ndarray | None = None
    K: np.ndarray | None = None
    phi: np.ndarray | None = None
    w_r: np.ndarray | None = None
    c_r: np.ndarray | None = None

    def __post_init__(self):
        if self.K is not None:
            self.K = np.atleast_2d(np.asarray(self.K, dtype=float))
            n = self.K.shape[0]
            for name in ("M", "C", "K"):
                A = getattr(self, name)
                A = np.zeros((n, n)) if A is None else np.atleast_2d(np.asarray(A, dtype=float))
                if A.shape != (n, n):
                    raise ValueError(f"{name} must be a ({n}, {n}) matrix, got shape {A.shape}")
                if not np.all(np.isfinite(A)):
                    bad = tuple(int(i) for i in np.argwhere(~np.isfinite(A))[0])
                    raise ValueError(f"{name} must be finite, got {A[bad]} at entry {bad}")
                if not np.allclose(A, A.T, rtol=0.0, atol=SYMMETRY_TOL * np.abs(A).max()):
                    raise ValueError(f"{name} must be symmetric")
                setattr(self, name, A)
            if self.phi is None:
                self._try_modal()
        elif self.phi is None:
            raise ValueError("a linear model needs M, C, K matrices or modal data (phi, w_r, c_r)")
        else:
            self.phi = np.atleast_2d(np.asarray(self.phi, dtype=float))
            r = self.phi.shape[1]
            self.w_r = np.asarray(self.w_r, dtype=float).reshape(r)
            self.c_r = np.zeros(r) if self.c_r is None else np.asarray(self.c_r, dtype=float).reshape(r)
            if not all(np.all(np.isfinite(a)) for a in (self.phi, self.w_r, self.c_r)):
                raise ValueError("modal data (phi, frequencies, damping) must be finite")
            if np.any(self.w_r < 0) or np.any(self.c_r < 0):
                raise ValueError("modal frequencies and damping must be >= 0")

    @property
    def n(self) -> int:
        return self.K.shape[0] if self.K is not None else self.phi.shape[0]

    @property
    def modal(self) -> bool:
        return self.phi is not None

    def _try_modal(self):
        """Use modes when M is SPD and C is diagonal in them (proportional damping)."""
        try:
            lam, phi = _eigh_general(self.K, self.M)
        except (np.linalg.LinAlgError, ValueError):
            return  # M singular or not SPD: direct solves only
        Cm = phi.T @ self.C @ phi
        off = Cm - np.diag(np.diag(Cm))
        if np.linalg.norm(off) > MODAL_DAMPING_TOL * max(np.linalg.norm(Cm), 1e-300):
            return
        self.phi, self.w_r = phi, np.sqrt(np.clip(lam, 0.0, None))
        self.c_r = np.diag(Cm).copy()

    def block(self, Omega: float) -> tuple[np.ndarray, np.ndarray]:
        """(K - Omega^2 M, Omega C) for the real pair form; needs matrices."""
        return self.K - Omega**2 * self.M, Omega * self.C

    def receptance(self, Omega: float, rows, cols, deriv: bool = False):
        """G[rows, cols] at Omega (complex) and, if deriv, dG/dOmega.

        Parameters
        ----------
        Omega : float   angular frequency of the harmonic [rad/s]
        rows, cols : index arrays, or None for all DOFs

        Returns
        -------
        G : (len(rows), len(cols)) complex
        dG : same shape, or None
        """
        rows = np.arange(self.n) if rows is None else np.asarray(rows)
        cols = np.arange(self.n) if cols is None else np.asarray(cols)
        if self.modal:
            den = self.w_r**2 - Omega**2 + 1j * Omega * self.c_r
            if np.any(den == 0):
                raise RuntimeError(f"undamped resonance of the linear part at Omega = {Omega:g} rad/s")
            g = 1.0 / den
            A, B = self.phi[rows], self.phi[cols]
            G = (A * g) @ B.T
            if not deriv:
                return G, None
            dg = -(-2.0 * Omega + 1j * self.c_r) * g**2
            return G, (A * dg) @ B.T
        Z = self.K - Omega**2 * self.M + 1j * Omega * self.C
        # Z is complex symmetric (M, C, K symmetric), so G = Z^-1 is too: its rows
        # are the transposed columns, one solve with the union of both index sets.
        both = np.union1d(rows, cols)
        I = np.zeros((self.n, both.size), dtype=complex)
        I[both, np.arange(both.size)] = 1.0
        try:
            Y = np.linalg.solve(Z, I)
        except np.linalg.LinAlgError as err:
            raise RuntimeError(f"singular dynamic stiffness at Omega = {Omega:g} rad/s") from err
        if not np.all(np.isfinite(Y)):
            raise RuntimeError(f"singular dynamic stiffness at Omega = {Omega:g} rad/s")
        pos = {int(d): i for i, d in enumerate(both)}
        Yc = Y[:, [pos[int(c)] for c in cols]]
        G = Yc[rows]
        if not deriv:
            return G, None
        Yr = Y[:, [pos[int(r)] for r in rows]]
        dZ = -2.0 * Omega * self.M + 1j * self.C
        return G, -(Yr.T @ dZ @ Yc)  # dG = -G dZ G, restricted to (rows, cols)

    def receptances(self, Omegas, rows, cols, deriv: bool = False):
        """:meth:`receptance` at several frequencies: (k, len(rows), len(cols)) arrays.

        Modal data are evaluated for all frequencies in one product.
        """
        Om = np.asarray(Omegas, dtype=float)
        if not self.modal:
            pairs = [self.receptance(o, rows, cols, deriv) for o in Om]
            return (np.array([p[0] for p in pairs]),
                    np.array([p[1] for p in pairs]) if deriv else None)
        rows = np.arange(self.n) if rows is None else np.asarray(rows)
        cols = np.arange(self.n) if cols is None else np.asarray(cols)
        den = self.w_r**2 - Om[:, None] ** 2 + 1j * Om[:, None] * self.c_r
        if np.any(den == 0):
            raise RuntimeError(f"undamped resonance of the linear part at Omega in {Om} rad/s")
        g = 1.0 / den
        A, B = self.phi[rows], self.phi[cols]
        G = (A[None] * g[:, None, :]) @ B.T
        if not deriv:
            return G, None
        dg = -(-2.0 * Om[:, None] + 1j * self.c_r) * g**2
        return G, (A[None] * dg[:, None, :]) @ B.T

    def response(self, Omega: float, rows, f: np.ndarray, deriv: bool = False):
        """G[rows, :] @ f for a complex load f (n,), and its Omega derivative."""
        f = np.asarray(f, dtype=complex)
        rows = np.asarray(rows)
        if self.modal:
            den = self.w_r**2 - Omega**2 + 1j * Omega * self.c_r
            q = (self.phi.T @ f) / den
            x = self.phi[rows] @ q
            if not deriv:
                return x, None
            return x, self.phi[rows] @ (-(-2.0 * Omega + 1j * self.c_r) * q / den)
        Z = self.K - Omega**2 * self.M + 1j * Omega * self.C
        q = np.linalg.solve(Z, f)
        if not deriv:
            return q[rows], None
        dZ = -2.0 * Omega * self.M + 1j * self.C
        return q[rows], -np.linalg.solve(Z, dZ @ q)[rows]
