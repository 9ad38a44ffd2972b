"""ContactElement with two tangents (q = [s_x, s_y, p], the C core's 2D element) in
harmonic balance: its exact Jacobian, the 1D contact on a line, isotropy, and a
circular forcing against time integration with the same C element."""
import numpy as np
import pytest

from fmu_src.element import IwanElement
from harmonic_balance.contact import ContactElement, frictionless_statics
from harmonic_balance.fourier import FourierBasis
from harmonic_balance.kinematics import Kinematics
from harmonic_balance.linear import LinearModel
from harmonic_balance.model import Model, load_elements
from harmonic_balance.newton import newton
from harmonic_balance.residual import FullResidual
from harmonic_balance.timeint import march

#: Newton tolerance on |R| (forces of order 1 N).
NEWTON_TOL = 1e-11
#: Same law and Newton tolerance on both sides: the HB solutions agree to what Newton
#: guarantees, NEWTON_TOL on forces of order 1 N. Measured 3.1e-15 relative (revision
#: a12e5f1: quadratic convergence overshoots the stopping test, which one iteration
#: fewer on another platform may not).
SOLVE_RTOL = NEWTON_TOL
#: Central differences at 1e-7 of the coefficient scale (kinks away), relative.
FD_STEP, FD_RTOL = 1e-7, 1e-6
#: The required accuracy of HB against time integration (measured: see the test).
TI_RTOL = 5e-3
STEPS = 512
H = 7


def point_model(P, direction=(1.0, 0.0), phase_y=0.0, N0=1.0, dN=0.0, k=1.0, kt=2.0, kn=10.0,
                mu=0.3, c=0.1, iwan=False, plane=True):
    """Mass on a contact with normal z: q = [x, y, -z] (plane) or [x, -z] (line: the 1D
    contact of the same law). Springs k on x and y; z pressed by N0 (+ dN cos);
    forcing P cos along ``direction``, its y part shifted by ``phase_y``."""
    if iwan:
        fr = IwanElement.from_sliders(kt * np.array([0.5, 0.3, 0.2]), mu * N0 * np.array([0.2, 0.3, 0.5]),
                                      N_ref=N0)
    else:
        fr = IwanElement.jenkins(kt, mu)
    if plane:
        kin = Kinematics.contact([0, 1, 2], [0, 0, 1.0], [[1.0, 0, 0], [0, 1.0, 0]], np.eye(3))
        lin = LinearModel(M=np.eye(3), C=c * np.eye(3), K=np.diag([k, k, 0.0]))
        f1 = np.array([P * direction[0], P * direction[1] * np.exp(1j * phase_y), -dN])
        return Model(lin, [ContactElement(kin, kn, fr, name="c")], {0: np.array([0, 0, -N0]), 1: f1})
    kin = Kinematics.contact([0, 1], [0, 1.0], [1.0, 0], np.eye(2))
    lin = LinearModel(M=np.eye(2), C=c * np.eye(2), K=np.diag([k, 0.0]))
    return Model(lin, [ContactElement(kin, kn, fr, name="c")], {0: np.array([0, -N0]),
                                                                1: np.array([P, -dN])})


def solve_hb(make, P, omega, levels=8):
    b = FourierBasis(H)
    x = None
    for Pi in np.linspace(P / levels, P, levels):
        res = FullResidual(make(Pi), b)
        x = res.linear_guess(omega) if x is None else x
        x = newton(lambda z, r=res: r(z, omega)[:2], x, NEWTON_TOL).x
    return res, b, x


@pytest.mark.parametrize("iwan", [False, True])
def test_contact_jacobian_equals_central_differences(iwan):
    """dF/dU of the element (slip in two directions, N varying through lift-off)."""
    el = point_model(1.0, iwan=iwan).links[0]
    b = FourierBasis(3)
    rng = np.random.default_rng(7)
    U = np.zeros((b.nb, 3))
    U[1:, :2] = 0.4 * rng.normal(size=(b.nb - 1, 2))       # slips ~ mu N / kt
    U[0, 2], U[1, 2] = 0.1, 0.12                             # p = 0.1 + 0.12 cos: lifts off
    out = el.evaluate(U, b, 1.0)
    step = FD_STEP * np.abs(U).max()
    fd = np.empty_like(out.dF)
    for i in range(U.size):
        e = np.zeros(U.size)
        e[i] = step
        Fp = el.evaluate((U.ravel() + e).reshape(U.shape), b, 1.0, jac=False).F.ravel()
        Fm = el.evaluate((U.ravel() - e).reshape(U.shape), b, 1.0, jac=False).F.ravel()
        fd[:, i] = (Fp - Fm) / (2 * step)
    assert np.abs(fd - out.dF).max() <= FD_RTOL * np.abs(out.dF).max()
    assert (out.f[:, 2] == 0).any() and out.W > 0


@pytest.mark.parametrize("iwan", [False, True])
def test_driven_along_x_is_the_1d_contact(iwan):
    omega, P = 1.1, 0.5
    res3, b, x3 = solve_hb(lambda p: point_model(p, iwan=iwan), P, omega)
    res2, _, x2 = solve_hb(lambda p: point_model(p, iwan=iwan, plane=False), P, omega)
    X3, X2 = x3.reshape(b.nb, 3), x2.reshape(b.nb, 2)
    assert np.abs(X3[:, 1]).max() <= SOLVE_RTOL * np.abs(X2[:, 0]).max()          # no y motion
    assert np.allclose(X3[:, [0, 2]], X2, rtol=0, atol=SOLVE_RTOL * np.abs(X2).max())
    l3, l2 = res3.evaluate(x3, omega)[0], res2.evaluate(x2, omega)[0]
    assert abs(l3.W - l2.W) <= SOLVE_RTOL * l2.W and l2.W > 0


def test_diagonal_forcing_is_isotropic():
    """Forcing along (1, 1)/sqrt(2): the motion and the friction force along the diagonal
    are the 1D contact's, nothing across."""
    omega, P = 0.9, 0.5
    d = np.array([1.0, 1.0]) / np.sqrt(2)
    res3, b, x3 = solve_hb(lambda p: point_model(p, direction=d), P, omega)
    res2, _, x2 = solve_hb(lambda p: point_model(p, plane=False), P, omega)
    X3, X2 = x3.reshape(b.nb, 3), x2.reshape(b.nb, 2)
    scale = np.abs(X2).max()
    assert np.allclose(X3[:, :2] @ d, X2[:, 0], rtol=0, atol=SOLVE_RTOL * scale)
    assert np.abs(X3[:, :2] @ np.array([-d[1], d[0]])).max() <= SOLVE_RTOL * scale
    f3, f2 = res3.evaluate(x3, omega)[0].f, res2.evaluate(x2, omega)[0].f
    assert np.allclose(f3[:, :2] @ d, f2[:, 0], rtol=0, atol=SOLVE_RTOL * np.abs(f2).max())


#: Circular forcing (P cos along x, P sin along y), HB (H = 7) against time integration
#: (512 steps a period, the same C element stepped from rest): measured friction energy
#: per cycle 2.8e-5, 1.9e-5, 1.0e-4 and peak |x| 6.0e-5, 3.2e-5, 3.6e-5 (constant N,
#: N varying, Iwan with N varying); the issue asks for 0.5 %.
@pytest.mark.slow
@pytest.mark.parametrize("dN, iwan", [(0.0, False), (0.4, False), (0.4, True)],
                         ids=["jenkins", "jenkins_varying_N", "iwan_varying_N"])
def test_circular_forcing_matches_time_integration(dN, iwan):
    omega, P = 1.0, 0.33
    make = lambda p: point_model(p, direction=(1.0, 1.0), phase_y=-np.pi / 2, dN=dN, iwan=iwan)  # noqa: E731
    res, b, x = solve_hb(make, P, omega)
    loop = res.evaluate(x, omega)[0]
    X = x.reshape(b.nb, 3)
    radius = np.hypot(loop.q[:, 0], loop.q[:, 1])
    assert radius.min() > 0.5 * radius.max() and np.ptp(X[1:, 1]) > 0   # a two-direction orbit
    ti = march(make(P), omega, STEPS)
    assert ti.converged
    (W_ti,) = ti.W_elements
    assert abs(loop.W - W_ti) <= TI_RTOL * W_ti
    assert abs(b.peak_abs(X[:, 0]) - ti.amplitude) <= TI_RTOL * ti.amplitude


def test_elements_toml_with_two_tangents(tmp_path):
    (tmp_path / "e.toml").write_text(
        '[[element]]\ntype = "contact"\ndofs = [0, 1, 2]\nnormal = [0.0, 0.0, 1.0]\n'
        'tangent = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]\nk_n = 10.0\nk_t = 2.0\nmu = 0.3\n'
        'slip_ref = [1e-3, -2e-3]\n')
    (el,) = load_elements(tmp_path / "e.toml")
    assert el.m == 3 and np.array_equal(el.slip_ref, [1e-3, -2e-3])
    assert np.array_equal(el.stuck_stiffness(), np.diag([2.0, 2.0, 10.0]))
    (tmp_path / "bad.toml").write_text((tmp_path / "e.toml").read_text().replace(
        "slip_ref = [1e-3, -2e-3]", "slip_ref = [1e-3, -2e-3, 0.0]"))
    with pytest.raises(ValueError, match=r"slip_ref: no allowed form fits"):
        load_elements(tmp_path / "bad.toml")


def test_frictionless_statics_gives_the_2d_prestress_slip():
    model = point_model(0.0)
    model.linear.K[0, 0] = model.linear.K[1, 1] = 1.0
    model.forcing[0] = np.array([0.3, -0.2, -1.0])       # a static tangential load too
    x, slip = frictionless_statics(model, apply=True)
    assert np.allclose(slip[0], [0.3, -0.2]) and np.allclose(model.links[0].slip_ref, [0.3, -0.2])
