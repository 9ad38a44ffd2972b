"""Fourier basis: DFT pair, derivative, peak search, sampling checks."""
import numpy as np
import pytest
from hbcases import SEED

from harmonic_balance.fourier import FourierBasis, default_samples, parse_harmonics

#: Round-off level of a DFT of a few hundred samples.
DFT_TOL = 1e-12


@pytest.mark.parametrize("spec", ["all:5", "odd:7", [0, 2, 3]])
def test_forward_dft_inverts_the_sampling(spec):
    b = FourierBasis(parse_harmonics(spec))
    np.testing.assert_allclose(b.D @ b.E, np.eye(b.nb), atol=DFT_TOL)


def test_ordering_is_mean_then_cos_sin_pairs():
    b = FourierBasis((0, 1, 3))
    assert b.nb == 5 and list(b.order) == [0, 1, 1, 3, 3]
    assert b.index(3) == (3, 4) and b.index(0) == (0, None)
    th = 0.7
    np.testing.assert_allclose(b.evaluate(np.array([0, 0, 0, 1.0, 0]), th), np.cos(3 * th))
    np.testing.assert_allclose(b.evaluate(np.array([0, 0, 0, 0, 1.0]), th), np.sin(3 * th))


def test_derivative_matrix_matches_finite_difference():
    b = FourierBasis("all:4")
    c = np.random.default_rng(SEED).normal(size=b.nb)
    th, h = 1.234, 1e-6
    fd = (b.evaluate(c, th + h) - b.evaluate(c, th - h)) / (2 * h)
    assert abs(b.evaluate(b.dtheta @ c, th) - fd) < 1e-8


def test_peak_abs_is_exact_not_grid_limited():
    b = FourierBasis("odd:5", n_t=32)
    c = np.random.default_rng(SEED).normal(size=b.nb)
    dense = np.abs(b.evaluate(c, np.linspace(0, 2 * np.pi, 400001))).max()
    assert abs(b.peak_abs(c) - dense) < 1e-9 * dense  # dense grid error ~ (2pi/4e5)^2


def test_peak_abs_at_high_harmonics_is_exact_and_agrees_with_the_fine_grid():
    # at H = 70 peak_abs searches a coarse grid and polishes every maximum near its top
    b = FourierBasis("all:70")
    rng = np.random.default_rng(SEED)
    for _ in range(5):
        c = rng.normal(size=b.nb) / (1.0 + b.order) ** 3   # a smooth response's decay
        dense = np.abs(b.evaluate(c, np.linspace(0, 2 * np.pi, 400001))).max()
        # dense grid error <= sum h^2 |c_h| (2 pi / 4e5)^2 / 8 ~ 1e-10 here
        assert abs(b.peak_abs(c) - dense) < 1e-9 * dense
        assert abs(b.peak_abs(c) - b._peak_abs_fine(c, 8)) <= 1e-13 * dense  # both exact


def test_too_few_samples_alias_and_are_refused():
    with pytest.raises(ValueError, match="alias"):
        FourierBasis("all:8", n_t=16)
    assert all(default_samples(H) > 8 * (2 * H + 1) for H in (1, 5, 9, 20))


@pytest.mark.parametrize("bad", ["odd:0", "even:3", "x", [], [-1, 1], [0]])
def test_bad_harmonic_specs_are_refused(bad):
    with pytest.raises(ValueError):
        parse_harmonics(bad)


def test_alias_ratio_flags_an_unresolved_signal():
    b = FourierBasis("all:3", n_t=64)
    th = 2 * np.pi * np.arange(64) / 64
    assert b.alias_ratio(np.cos(th)) < 1e-12
    assert b.alias_ratio(np.sign(np.cos(th))) > 1e-2  # square wave: 1/h tail


@pytest.mark.parametrize(("spec", "n_t"), [("all:5", 0), ("odd:7", 64), ([0, 2, 3], 0),
                                            ("all:5", 11)])
def test_weighted_transform_is_the_product_with_the_weights(spec, n_t):
    """D diag(k) E from the FFT of k (Toeplitz plus Hankel in the orders) equals the
    product, also on a grid so coarse that orders up to 2H wrap (n_t = 11, H = 5)."""
    b = FourierBasis(parse_harmonics(spec), n_t)
    k = np.random.default_rng(SEED).normal(size=(2, b.n_t))
    W = b.weighted(k)
    for j in range(2):
        np.testing.assert_allclose(W[j], (b.D * k[j]) @ b.E, rtol=0, atol=DFT_TOL)
    np.testing.assert_allclose(b.weighted(k[0]), W[0], rtol=0, atol=DFT_TOL)


def test_projection_of_sparse_terms_is_the_dense_product():
    """project_terms: D (diag(d) + sum_i c_i e_row e_col^T) E for a few anchor columns."""
    b = FourierBasis("all:6", 128)
    rng = np.random.default_rng(SEED)
    d = rng.normal(size=(2, b.n_t))
    row = rng.integers(0, b.n_t, 90)
    col = rng.choice([3, 40, 77], 90)
    row[row == col] += 1
    c = rng.normal(size=(2, 90))
    P = b.project_terms(d, row, col, c)
    for j in range(2):
        S = np.diag(d[j])
        np.add.at(S, (row, col), c[j])
        np.testing.assert_allclose(P[j], b.D @ S @ b.E, rtol=0, atol=DFT_TOL)
