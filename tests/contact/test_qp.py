"""The bounded-QP module shared by the normal and tangential solves."""
import numpy as np
import pytest
from scipy import linalg, optimize

from contact_core import qp

#: Seeds of the random box QPs, written out.
SEEDS = (11, 2026, 777)


def _random_box_qp(seed, n=50):
    rng = np.random.default_rng(seed)
    A = rng.standard_normal((n, n))
    K = A @ A.T / n + 0.05 * np.eye(n)
    b = rng.standard_normal(n)
    hi = rng.uniform(0.05, 0.5, n)
    return K, b, -hi, hi


@pytest.mark.parametrize("seed", SEEDS)
def test_projected_newton_matches_bvls_and_passes_its_kkt_check(seed):
    K, b, lo, hi = _random_box_qp(seed)
    res = qp.solve(K, b, lo, hi, gtol=1e-12)
    L = linalg.cholesky(K, lower=True)
    ref = optimize.lsq_linear(L.T, linalg.solve_triangular(L, b, lower=True), bounds=(lo, hi),
                              method="bvls", tol=1e-15)
    np.testing.assert_allclose(res.x, ref.x, atol=1e-9 * hi.max())
    qp.check_kkt(res.x, res.g, lo, hi, res.free, xtol=0.0, gtol=1e-10)
    assert 0 < res.free.sum() < b.size  # a mixed case: some variables at a bound


def test_fallback_and_no_fallback():
    K, b, lo, hi = _random_box_qp(SEEDS[0])
    ref = qp.solve(K, b, lo, hi, gtol=1e-12)
    fb = qp.solve(K, b, lo, hi, gtol=1e-12, max_iter=0)  # straight to BVLS
    np.testing.assert_allclose(fb.x, ref.x, atol=1e-9 * hi.max())
    with pytest.raises(RuntimeError, match="did not converge in 0 iterations"):
        qp.solve(K, b, lo, hi, gtol=1e-12, max_iter=0, fallback=False, name="test QP")


def test_kkt_check_reports_each_violation():
    K, b, lo, hi = _random_box_qp(SEEDS[1])
    res = qp.solve(K, b, lo, hi, gtol=1e-12)
    x = res.x.copy()
    x[~res.free] *= 1.01                               # beyond the bounds
    with pytest.raises(RuntimeError, match="leaves its bounds"):
        qp.check_kkt(x, K @ x - b, lo, hi, res.free, xtol=1e-9, gtol=1e-9)
    g = res.g.copy()
    g[np.flatnonzero(res.free)[0]] = 1e-3              # an interior variable not stationary
    with pytest.raises(RuntimeError, match="stationarity"):
        qp.check_kkt(res.x, g, lo, hi, res.free, xtol=1e-9, gtol=1e-9)
    g = res.g.copy()
    i = np.flatnonzero(~res.free)[0]
    g[i] = np.sign(res.x[i]) * 1e-3                    # a bound variable pushed inwards
    with pytest.raises(RuntimeError, match="pushed inwards"):
        qp.check_kkt(res.x, g, lo, hi, res.free, xtol=1e-9, gtol=1e-9)


def test_nonnegative_qp_with_infinite_upper_bounds():
    """The normal problem's form: bounds [0, inf) (an NNLS in Cholesky form)."""
    K, b, _, _ = _random_box_qp(SEEDS[2])
    n = b.size
    res = qp.solve(K, b, np.zeros(n), np.full(n, np.inf), gtol=1e-12)
    L = linalg.cholesky(K, lower=True)
    ref, _ = optimize.nnls(L.T, linalg.solve_triangular(L, b, lower=True))
    np.testing.assert_allclose(res.x, ref, atol=1e-9 * ref.max())
