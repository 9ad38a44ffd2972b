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


def compliance_block(K: sp.spmatrix, dofs: np.ndarray) -> np.ndarray:
    """Rows and columns ``dofs`` of K^-1: the compliance at those DOFs, shape (m, m).

    Solves K X = E for the unit vectors E of ``dofs`` in blocks of RHS_BLOCK.
    """
    solve = factorize(K)
    n, m = K.shape[0], dofs.size
    C = np.empty((m, m))
    for start in range(0, m, RHS_BLOCK):
        cols = dofs[start:start + RHS_BLOCK]
        B = np.zeros((n, cols.size))
        B[cols, np.arange(cols.size)] = 1.0
        C[:, start:start + cols.size] = solve(B)[dofs]
    return 0.5 * (C + C.T)  # symmetric by Maxwell-Betti; remove round-off asymmetry
