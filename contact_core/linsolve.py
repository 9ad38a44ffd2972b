"""Sparse symmetric positive-definite solves with many right-hand sides.

CHOLMOD (scikit-sparse, optional: ``pip install "scikit-sparse<0.5"`` after
``apt-get install libsuitesparse-dev``) when it imports, scipy's SuperLU
otherwise; both give the same answer to round-off. SuperLU is told the matrix is
symmetric (``MMD_AT_PLUS_A`` ordering, no pivoting) which keeps its fill close
to a Cholesky factor. ``DAMPER_SOLVER=scipy`` forces the fallback.
"""
from __future__ import annotations

import os

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla

#: Right-hand sides per block solve (bounds the dense work array).
RHS_BLOCK = 256


def backend() -> str:
    """Name of the solver used: "cholmod" or "superlu"."""
    if os.environ.get("DAMPER_SOLVER", "").lower() == "scipy":
        return "superlu"
    try:
        import sksparse.cholmod  # noqa: F401
    except ImportError:
        return "superlu"
    return "cholmod"


def factorize(K: sp.spmatrix):
    """Factor a sparse SPD matrix; return ``solve(B) -> X`` for dense B (n, m)."""
    if backend() == "cholmod":
        from sksparse.cholmod import cholesky
        factor = cholesky(sp.csc_matrix(K))
        return factor
    lu = spla.splu(sp.csc_matrix(K), permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                   options={"SymmetricMode": True})
    return lu.solve


def compliance_block(K: sp.spmatrix, dofs: np.ndarray, order: np.ndarray | None = None) -> np.ndarray:
    """Rows and columns ``dofs`` of K^-1: the compliance at those DOFs, shape (m, m).

    CHOLMOD: the DOFs are ordered last after a fill-reducing ordering of the
    rest, so the trailing block L22 of the Cholesky factor K = L L' satisfies
    L22 L22' = S, the Schur complement (condensed stiffness) on ``dofs``, and
    the compliance is S^-1 = L22^-T L22^-1: no solves with the whole factor.
    SuperLU with a fill-reducing ``order`` (a permutation of K's rows, e.g. the
    mesh's nested dissection): the same with K = L U, S = L22 U22. Otherwise
    (or if a factorisation re-orders the trailing block) K X = E is solved for
    the unit vectors E of ``dofs`` in blocks of RHS_BLOCK.
    """
    if backend() == "cholmod":
        C = _schur_compliance(sp.csc_matrix(K), dofs)
        if C is not None:
            return C
    elif order is not None:
        C = _schur_superlu(sp.csc_matrix(K), dofs, order)
        if C is not None:
            return C
    solve = factorize(K)
    n, m = K.shape[0], dofs.size
    C = np.empty((m, m))
    for start in range(0, m, RHS_BLOCK):
        cols = dofs[start:start + RHS_BLOCK]
        B = np.zeros((n, cols.size))
        B[cols, np.arange(cols.size)] = 1.0
        C[:, start:start + cols.size] = solve(B)[dofs]
    return 0.5 * (C + C.T)  # symmetric by Maxwell-Betti; remove round-off asymmetry


def _schur_compliance(K: sp.csc_matrix, dofs: np.ndarray) -> np.ndarray | None:
    """S^-1 from the trailing block of a Cholesky factor with ``dofs`` last (CHOLMOD)."""
    from sksparse.cholmod import analyze, cholesky

    n, m = K.shape[0], dofs.size
    order = analyze(K).P()
    is_dof = np.zeros(n, bool)
    is_dof[dofs] = True
    perm = np.concatenate([order[~is_dof[order]], dofs])
    factor = cholesky(K[perm][:, perm].tocsc(), ordering_method="natural")
    if not np.array_equal(factor.P(), np.arange(n)):
        return None
    L22 = factor.L()[n - m:, n - m:].toarray()
    Linv = sla.solve_triangular(L22, np.eye(m), lower=True, check_finite=False)
    C = Linv.T @ Linv
    return 0.5 * (C + C.T)


def _trailing_last(order: np.ndarray, dofs: np.ndarray, n: int) -> np.ndarray:
    """``order`` with ``dofs`` moved to the end (in the order given)."""
    is_dof = np.zeros(n, bool)
    is_dof[dofs] = True
    return np.concatenate([order[~is_dof[order]], dofs])


def _schur_superlu(K: sp.csc_matrix, dofs: np.ndarray, order: np.ndarray) -> np.ndarray | None:
    """S^-1 from the trailing blocks of K = L U (SuperLU, no pivoting) with ``dofs`` last."""
    n, m = K.shape[0], dofs.size
    if np.sort(order).size != n or not np.array_equal(np.sort(order), np.arange(n)):
        raise ValueError("order is not a permutation of the matrix rows")
    perm = _trailing_last(order, dofs, n)
    lu = spla.splu(K[perm][:, perm].tocsc(), permc_spec="NATURAL", diag_pivot_thresh=0.0,
                   options={"SymmetricMode": True})
    if not (np.array_equal(lu.perm_r, np.arange(n)) and np.array_equal(lu.perm_c, np.arange(n))):
        return None
    S = lu.L[n - m:, n - m:].toarray() @ lu.U[n - m:, n - m:].toarray()
    C = sla.inv(S, check_finite=False)
    return 0.5 * (C + C.T)
