"""Exact Jacobians of the HB residuals: finite differences and casadi AD."""
import casadi as ca
import numpy as np
import pytest
from hbcases import SEED, jenkins, sdof, two_dof
from jenkins_ref import JenkinsRef

from harmonic_balance.fourier import FourierBasis
from harmonic_balance.residual import CondensedResidual, FullResidual

#: Central differences of a piecewise-smooth residual with step 1e-7 relative:
#: truncation + round-off ~1e-8 of the entries, unless a stick/slip switch is
#: crossed (rare at random points); 1e-6 of the largest entry leaves margin.
FD_RTOL = 1e-6
#: casadi and numpy evaluate the same arithmetic in other orders: round-off of
#: sums over n_t = 256 samples, ~1e-13 relative.
AD_RTOL = 1e-11


def fd_jacobian(f, x, h):
    J = np.empty((f(x).size, x.size))
    for j in range(x.size):
        e = np.zeros_like(x)
        e[j] = h
        J[:, j] = (f(x + e) - f(x - e)) / (2 * h)
    return J


def random_point(n, scale):
    return np.random.default_rng(SEED).normal(scale=scale, size=n)


@pytest.mark.parametrize("spec", ["all:1", "all:5", "odd:7"])
def test_full_residual_jacobian_matches_finite_differences(spec):
    model = sdof()
    res = FullResidual(model, FourierBasis(spec))
    x, w = random_point(res.size, 0.1), 1.07  # ~2x the slip displacement fs/kt = 0.05
    R, J, Jw = res(x, w)
    Jfd = fd_jacobian(lambda z: res(z, w, jac=False), x, 1e-8)
    assert np.abs(J - Jfd).max() <= FD_RTOL * np.abs(J).max()
    Jw_fd = (res(x, w + 1e-7, jac=False) - res(x, w - 1e-7, jac=False)) / 2e-7
    assert np.abs(Jw - Jw_fd).max() <= FD_RTOL * np.abs(Jw).max()


@pytest.mark.parametrize("c_prop", [True, False])
def test_condensed_residual_jacobian_matches_finite_differences(c_prop):
    model = two_dof(c_prop)
    res = CondensedResidual(model, FourierBasis("all:3"))
    assert model.linear.modal == c_prop
    x, w = random_point(res.size, 0.15), 1.3
    R, J, Jw = res(x, w)
    Jfd = fd_jacobian(lambda z: res(z, w, jac=False), x, 1e-8)
    assert np.abs(J - Jfd).max() <= FD_RTOL * np.abs(J).max()
    Jw_fd = (res(x, w + 1e-7, jac=False) - res(x, w - 1e-7, jac=False)) / 2e-7
    assert np.abs(Jw - Jw_fd).max() <= FD_RTOL * np.abs(Jw).max()


def casadi_sdof_residual(basis, m, c, k, kt, fs, P, w, x_num):
    """Same residual written in casadi: the Jenkins play operator with fmax/fmin.

    The sweep starts at the sample of largest u (taken from the numeric point, as
    the C core does), with the slider hanging on it.
    """
    X = ca.SX.sym("X", basis.nb)
    E, D = ca.DM(basis.E), ca.DM(basis.D)
    u = E @ X
    i0 = int(np.argmax(basis.E @ x_num))
    d = fs / kt
    z = u[i0] - d
    F = [None] * basis.n_t
    for s in range(1, basis.n_t + 1):
        i = (i0 + s) % basis.n_t
        z = ca.fmin(ca.fmax(z, u[i] - d), u[i] + d)
        F[i] = kt * (u[i] - z)
    h = basis.order.astype(float)
    A = np.diag(k - m * (h * w) ** 2) + c * w * basis.dtheta
    f = np.zeros(basis.nb)
    f[basis.index(1)[0]] = P
    R = ca.DM(A) @ X + D @ ca.vertcat(*F) - ca.DM(f)
    fun = ca.Function("R", [X], [R, ca.jacobian(R, X)])
    Rn, Jn = fun(x_num)
    return np.array(Rn).ravel(), np.array(Jn)


def test_jacobian_matches_casadi_automatic_differentiation():
    basis = FourierBasis("odd:5")
    model = sdof()
    res = FullResidual(model, basis)
    x, w = random_point(res.size, 0.1), 1.1
    R, J, _ = res(x, w)
    Rc, Jc = casadi_sdof_residual(basis, 1.0, 0.01, 1.0, 1.0, 0.05, 0.05, w, x)
    assert np.abs(R - Rc).max() <= AD_RTOL * np.abs(R).max()
    assert np.abs(J - Jc).max() <= AD_RTOL * np.abs(J).max()


def test_c_element_jacobian_equals_the_oracle():
    basis = FourierBasis("all:4")
    X = random_point(basis.nb, 0.3)
    u = basis.E @ X
    got = jenkins(1.5, 0.2).periodic_jac(u, basis.E)
    ref = JenkinsRef(1.5, 0.2).periodic_jac(u, basis.E)
    np.testing.assert_allclose(got[0], ref[0], atol=1e-14)
    np.testing.assert_allclose(got[1], ref[1], atol=1e-13)
    assert abs(got[3] - ref[3]) <= 1e-13
