"""The node solve's linear algebra: contact-row products and the factor cache's solves.

:class:`harmonic_balance.massless.Rows` (gathers and scatters for rows of one entry) against
dense products, and :meth:`harmonic_balance.massless.FactorCache.solve_diagonal` (Woodbury
updates of kept reference inverses) against direct solves, on random operators of the
surface's kind: a symmetric positive definite A plus contact stiffnesses on its diagonal.
"""
from __future__ import annotations

import numpy as np
import pytest

from harmonic_balance.massless import MAX_REFERENCES, REFERENCE_SHARE, FactorCache, Rows

#: Seed of the random operators (written out: any seed must pass).
SEED = 20261128
#: Solves through a Woodbury update against direct ones, relative to the solution's largest
#: entry: round-off amplified by the operators' condition (~1e3 here); measured ~1e-14.
SOLVE_RTOL = 1e-11


def _operator(rng, m: int) -> np.ndarray:
    """A symmetric positive definite (m, m), dense as a condensed body's node stiffness."""
    B = rng.standard_normal((m, m))
    return B @ B.T / m + np.eye(m)


@pytest.mark.parametrize("rows_per_entry", [1, 2], ids=["one_entry", "two_entries"])
def test_rows_products_equal_the_dense_products(rows_per_entry):
    rng = np.random.default_rng(SEED)
    n_c, n_b = 12, 30
    Q = np.zeros((n_c, n_b))
    cols = rng.permutation(n_b)[:n_c * rows_per_entry].reshape(n_c, rows_per_entry)
    Q[np.arange(n_c)[:, None], cols] = rng.standard_normal(cols.shape)
    Q[3] = 0.0                                              # a contact without this kind of row
    R = Rows(Q)
    assert R.gather == (rows_per_entry == 1)
    X, Y = rng.standard_normal((2, n_b, 4)), rng.standard_normal((2, n_c, 4))
    assert np.allclose(R.rows(X), np.einsum("cb,hbd->hcd", Q, X), rtol=1e-15, atol=0.0)
    assert np.allclose(R.cols(Y), np.einsum("cb,hcd->hbd", Q, Y), rtol=1e-15, atol=0.0)
    assert np.allclose(R.rows(X[..., 0]), X[..., 0] @ Q.T, rtol=1e-15, atol=0.0)


def test_diagonal_updates_solve_as_direct_solves_through_reference_changes():
    """A sequence of diagonals: a few entries changed (updates of the first reference), most
    changed (a new reference), and more distinct states than references kept."""
    rng = np.random.default_rng(SEED)
    m = 40
    A = _operator(rng, m)
    stuck = rng.uniform(1.0, 2.0, m)
    cache = FactorCache()
    diagonals = [stuck]
    for share in (0.1, 0.2, 0.9, 0.5, 1.0, 0.05, 0.7, 0.95, 0.3):
        d = stuck.copy()
        changed = rng.permutation(m)[:int(share * m)]
        d[changed] = rng.choice([0.0, 0.5], changed.size)   # slipping or open nodes
        diagonals.append(d)
    for i, d in enumerate(diagonals + diagonals[::-1]):
        for rhs in (rng.standard_normal(m), rng.standard_normal((m, 3))):
            x = cache.solve_diagonal("block", ("case", d.tobytes()), A, d, rhs)
            x_ref = np.linalg.solve(A + np.diag(d), rhs)
            assert np.abs(x - x_ref).max() <= SOLVE_RTOL * np.abs(x_ref).max(), i
    refs = cache._inv["block"]
    assert 1 < len(refs) <= MAX_REFERENCES
    # every kept reference is an operator met, and the last one met differs little from one
    last = diagonals[0]
    assert min(np.count_nonzero(last != d_r) for d_r, _ in refs.values()) <= REFERENCE_SHARE * m
