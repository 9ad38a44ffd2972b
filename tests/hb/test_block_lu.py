"""Block-tridiagonal LU of a chain's harmonic-balance Jacobian (harmonic_balance.block_lu)."""
import numpy as np
import pytest

from harmonic_balance import block_lu
from harmonic_balance.block_lu import chain_order, factor

SEED = 20261127
#: Relative residual of a solve: a few hundred ulp of a well-conditioned system of ~30 unknowns.
SOLVE_RTOL = 1e-11


def _chain_matrix(rng, nb, order, k):
    """A random (nb n + k) matrix in coefficient-major layout coupling only neighbours of
    ``order`` (dense DOF blocks), with a border of width k."""
    n = len(order)
    A4 = np.zeros((nb, n, nb, n))
    for a, b in zip(order, order[1:]):
        A4[:, a, :, b] = rng.normal(size=(nb, nb))
        A4[:, b, :, a] = rng.normal(size=(nb, nb))
    for d in order:
        A4[:, d, :, d] = rng.normal(size=(nb, nb)) + 4.0 * np.sqrt(nb) * np.eye(nb)
    N = nb * n
    A = np.zeros((N + k, N + k))
    A[:N, :N] = A4.reshape(N, N)
    if k:
        A[:N, N:] = rng.normal(size=(N, k))
        A[N:] = rng.normal(size=(k, N + k))
    return A


@pytest.mark.parametrize("k", [0, 1])
def test_block_lu_solves_and_signs_like_the_dense_lu(k):
    rng = np.random.default_rng(SEED)
    order = [2, 0, 3, 1]   # the chain need not be in index order
    A = _chain_matrix(rng, 7, order, k)
    f = factor(A, order, 7, 4)
    r = rng.normal(size=A.shape[0])
    z = f.solve(r)
    assert np.linalg.norm(A @ z - r) <= SOLVE_RTOL * np.linalg.norm(r)
    assert f.det_sign() == np.linalg.slogdet(A)[0]


def test_block_lu_with_border_is_regular_at_a_fold():
    # the unbordered part singular (a fold of the branch), the bordered matrix regular
    rng = np.random.default_rng(SEED + 1)
    order = [0, 1, 2]
    A = _chain_matrix(rng, 5, order, 1)
    N = 15
    # make the last DOF's Schur complement singular by changing its own block only
    last = np.arange(5) * 3 + 2                 # DOF 2's unknowns (coefficient-major)
    rest = np.setdiff1d(np.arange(N), last)
    S = A[np.ix_(last, last)] - A[np.ix_(last, rest)] @ np.linalg.solve(A[np.ix_(rest, rest)],
                                                                         A[np.ix_(rest, last)])
    u, s, vt = np.linalg.svd(S)
    A[np.ix_(last, last)] -= s[-1] * np.outer(u[:, -1], vt[-1])
    assert np.linalg.matrix_rank(A[:N, :N]) == N - 1
    f = factor(A, order, 5, 3)
    r = rng.normal(size=N + 1)
    assert np.linalg.norm(A @ f.solve(r) - r) <= SOLVE_RTOL * np.linalg.cond(A) * np.linalg.norm(r)


def test_chain_order_finds_a_path_and_refuses_other_graphs():
    path = chain_order(4, {(0, 2), (2, 3), (3, 1), (1, 1)})
    assert path in ([0, 2, 3, 1], [1, 3, 2, 0])
    assert chain_order(3, {(0, 1), (1, 2), (2, 0)}) is None          # a cycle
    assert chain_order(4, {(0, 1), (0, 2), (0, 3)}) is None          # a star
    assert chain_order(4, {(0, 1), (2, 3)}) is None                  # two pieces


#: Refined peak of the same curve with block and dense LU: both corrected to the Newton
#: tolerance (1e-10 of |F|), the peak refined by Brent to its tolerance; the amplitude is
#: flat there, so round-off of the solves moves it far less than this.
SAME_PEAK_RTOL = 1e-7


def test_chain_curve_is_the_same_with_the_block_lu(monkeypatch):
    from harmonic_balance.bench_models import chain5
    from harmonic_balance.frf import FRFProblem, compute_frf

    case = chain5()   # every DOF carries a link: the full residual, a chain of 5 DOFs
    H = 15
    model = case.model()
    monkeypatch.setattr(block_lu, "MIN_NB", 1)   # the block LU at this (small) H too
    assert FRFProblem(model, H).factorize is not None
    band = (0.45, 0.65)   # around the highest peak (omega 0.54)
    block = compute_frf(model, H, band, truncation_check=False, stability=False)
    monkeypatch.setattr(block_lu, "MIN_NB", 10**9)
    assert FRFProblem(model, H).factorize is None
    dense = compute_frf(model, H, band, truncation_check=False, stability=False)
    assert abs(block.peak_amplitude - dense.peak_amplitude) <= SAME_PEAK_RTOL * dense.peak_amplitude
    assert abs(block.peak_omega - dense.peak_omega) <= SAME_PEAK_RTOL * dense.peak_omega
