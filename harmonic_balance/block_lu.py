"""LU factors of a harmonic-balance Jacobian that is block tridiagonal in its DOFs.

Knows nothing about mechanics: a square matrix A of size N + k (k = 0 or 1: a
continuation's bordering row and column) whose leading N = n_b n rows and columns hold
unknowns in the coefficient-major order of :mod:`.fourier` (coefficient c of DOF d at
``c n + d``), and an order p of the n DOFs in which A couples each DOF only to itself
and its two neighbours: the DOF blocks ``A_ij`` (n_b, n_b) vanish for |i - j| > 1 (a
chain of masses whose links join neighbours: the linear part is block diagonal in the
harmonics, a link dense in them).

Factorisation (block Gaussian elimination; Golub & Van Loan, Matrix Computations,
sec. 4.5.1, with the border carried along as an arrowhead): with S_0 = A_00,
``X_i = S_i^-1 [A_i,i+1, b_i]``, ``S_i+1 = A_i+1,i+1 - A_i+1,i X_i[:, :n_b]``, the border
column and row updated alike, and the last block factored together with the border
(``[S_n-1, b; c^T, e]``), each S_i by LAPACK's LU with partial pivoting. The border in
the last block keeps the factorisation regular at a fold, where the Jacobian without it
is singular. det A = prod det S_i. Cost O(n n_b^3) against the dense O(n^3 n_b^3):
measured on the 5-mass chain at H = 31 (316 unknowns) 0.6 ms against 0.9 ms.

The eliminated blocks S_0 ... S_n-2 are pivoted only within themselves: when one is
singular (a DOF subsystem at its own resonance with the rest held) the factorisation
reports it (:func:`factor` returns None) and the caller falls back to the dense LU.
"""
from __future__ import annotations

import numpy as np
from scipy.linalg.lapack import dgesv, dgetrf, dgetrs

#: Coefficients per DOF (n_b = 2 H + 1) and DOFs from which :func:`chain_factorizer` factors
#: by blocks. Measured on 5 DOFs with the border, block against dense: n_b 31 0.17 / 0.14
#: ms, 43 0.31 / 0.43, 63 0.58 / 0.87, 95 1.5 / 2.6, 141 3.9 / 8.3 (below n_b 43 the
#: dense LU's fewer calls win).
MIN_NB = 43
MIN_DOFS = 3


class BlockTridiagonalLU:
    """Factors of A (module docstring); :meth:`solve` and :meth:`det_sign` as the dense
    factors' :func:`.newton.lu_solve` and :func:`.newton.lu_det_sign`."""

    def __init__(self, order, nb: int, n: int, k: int):
        self.order, self.nb, self.n, self.k = list(order), nb, n, k
        self.lus, self.X, self.L, self.C = [], [], [], []
        self.last = None

    def _split(self, v: np.ndarray):
        """Per-DOF parts (n_b,) of a vector (N + k,) in the order, and its border (k,)."""
        N = self.nb * self.n
        V = v[:N].reshape(self.nb, self.n)
        return [V[:, d] for d in self.order], v[N:]

    def solve(self, r: np.ndarray) -> np.ndarray:
        """z (N + k,) with A z = r."""
        parts, rb = self._split(np.asarray(r, dtype=float))
        rb = rb.copy()
        w, g = [], parts[0]
        for i, (lu, piv) in enumerate(self.lus):
            wi = dgetrs(lu, piv, g)[0]
            w.append(wi)
            g = parts[i + 1] - self.L[i] @ wi
            if self.k:
                rb -= self.C[i] @ wi
        lu, piv = self.last
        zl = dgetrs(lu, piv, np.concatenate([g, rb]))[0]
        z = [None] * self.n
        z[-1], zb = zl[:self.nb], zl[self.nb:]
        for i in range(self.n - 2, -1, -1):
            z[i] = w[i] - self.X[i] @ np.concatenate([z[i + 1], zb])
        out = np.empty(self.nb * self.n + self.k)
        O = out[:self.nb * self.n].reshape(self.nb, self.n)
        for d, zi in zip(self.order, z):
            O[:, d] = zi
        out[self.nb * self.n:] = zb
        return out

    def det_sign(self) -> float:
        """Sign of det(A): the product over the blocks' LU factors."""
        s = 1.0
        for lu, piv in [*self.lus, self.last]:
            swaps = np.count_nonzero(piv != np.arange(len(piv))) % 2
            s *= (-1.0) ** swaps * np.prod(np.sign(np.diag(lu)))
        return float(s)


def factor(A: np.ndarray, order, nb: int, n: int):
    """:class:`BlockTridiagonalLU` of A (N + k, N + k), N = nb n, the DOFs in ``order``
    (module docstring), or None when a block is exactly singular."""
    N = nb * n
    k = A.shape[0] - N
    A4 = A[:N, :N].reshape(nb, n, nb, n)
    f = BlockTridiagonalLU(order, nb, n, k)
    p = f.order
    S = np.array(A4[:, p[0], :, p[0]])
    bb = np.array(A[:N, N:].reshape(nb, n, k)[:, p[0], :])
    cc = np.array(A[N:, :N].reshape(k, nb, n)[:, :, p[0]])
    E = np.array(A[N:, N:])
    for i in range(n - 1):
        # S_i's factors and X_i = S_i^-1 [A_i,i+1, b_i] in one LAPACK call
        lu, piv, X, info = dgesv(S, np.hstack([A4[:, p[i], :, p[i + 1]], bb]))
        if info != 0:
            return None
        Lo = np.array(A4[:, p[i + 1], :, p[i]])
        f.lus.append((lu, piv))
        f.X.append(X)
        f.L.append(Lo)
        f.C.append(cc)
        S = A4[:, p[i + 1], :, p[i + 1]] - Lo @ X[:, :nb]
        bb = A[:N, N:].reshape(nb, n, k)[:, p[i + 1], :] - Lo @ X[:, nb:]
        if k:
            Y = cc @ X
            cc = A[N:, :N].reshape(k, nb, n)[:, :, p[i + 1]] - Y[:, :nb]
            E = E - Y[:, nb:]
    lu, piv, info = dgetrf(np.block([[S, bb], [cc, E]]) if k else S)
    if info != 0:
        return None
    f.last = (lu, piv)
    return f


def chain_order(n: int, couplings) -> list | None:
    """An order of n DOFs in which every coupled pair are neighbours (a path), or None.

    ``couplings``: pairs (i, j) of coupled DOFs (either order, self-pairs ignored).
    """
    adj = [set() for _ in range(n)]
    for i, j in couplings:
        if i != j:
            adj[i].add(j)
            adj[j].add(i)
    if n < 2 or any(len(a) > 2 for a in adj):
        return None
    ends = [d for d in range(n) if len(adj[d]) <= 1]
    if not ends:
        return None  # a cycle
    order, prev = [ends[0]], None
    while len(order) < n:
        nxt = [d for d in adj[order[-1]] if d != prev]
        if not nxt:
            return None  # more than one component: keep it simple
        prev = order[-1]
        order.append(nxt[0])
    return order


def chain_factorizer(nb: int, n: int, couplings):
    """A factorisation A -> factors for Jacobians of n DOFs with nb coefficients each:
    :func:`factor` in the DOFs' chain order (the dense :func:`.newton.lu_factor` where a
    block is singular), or None when the DOFs form no chain of at least MIN_DOFS or the
    blocks are smaller than MIN_NB (the dense LU is then the faster)."""
    from .newton import lu_factor

    order = chain_order(n, couplings) if nb >= MIN_NB and n >= MIN_DOFS else None
    if order is None:
        return None

    def factorize(A):
        f = factor(A, order, nb, n)
        return f if f is not None else lu_factor(A)
    return factorize
