"""Multi-DOF models: receptance condensation, modal data, zeroth harmonic, failures."""
import numpy as np
import pytest
import scipy.linalg as sla
from hbcases import jenkins, two_dof

from harmonic_balance.aft import FrictionLink
from harmonic_balance.frf import FRFError, FRFProblem, compute_frf
from harmonic_balance.linear import LinearModel
from harmonic_balance.model import Model
from harmonic_balance.newton import newton

#: Condensation is exact algebra: the same solution at the same frequency, Newton to
#: 1e-14. Measured 1.4e-14 (revision a12e5f1); 1e-12 for other BLAS builds and threads.
EXACT_RTOL = 1e-12
#: Refined peaks of two runs (condensed and full, modal and matrices): each peak is
#: refined to 1e-6 in frequency, so two may differ by 2e-6; measured 7.7e-7 (a12e5f1):
#: 1e-5. The amplitude is flat at the peak (error ~ the frequency error squared over the
#: damping): measured 4.7e-10 (a12e5f1); 1e-7 covers what the frequency tolerance allows.
PEAK_RTOL, PEAK_OMEGA_RTOL = 1e-7, 1e-5
#: Energy balance of the exact links at the curve's solutions (Newton tolerance of the
#: continuation): measured 2.3e-9 of the input work (a12e5f1); 130x.
ENERGY_RTOL = 3e-7


def chain(n=5, c_prop=True):
    """n masses in a chain, a Jenkins element between DOFs 2 and 3, response at DOF 0."""
    M = np.diag(np.linspace(1.0, 0.6, n))
    K = 2 * np.eye(n) - np.eye(n, k=1) - np.eye(n, k=-1)
    C = 0.02 * M + 0.002 * K if c_prop else np.diag(np.r_[0.03, np.zeros(n - 1)])
    f = np.zeros(n)
    f[0] = 0.02
    links = [FrictionLink(jenkins(0.6, 0.01), 2, 3), FrictionLink(jenkins(0.3, 0.02), 4)]
    return Model(LinearModel(M=M, C=C, K=K), links, {1: f}, response_dof=0)


@pytest.mark.parametrize("make, band", [(lambda: two_dof(True), (0.9, 1.3)),
                                        (lambda: two_dof(False), (0.9, 1.3)),
                                        (lambda: chain(5, True), (1.0, 1.3)),
                                        (lambda: chain(5, False), (0.45, 0.7))])
def test_condensed_and_full_residuals_give_the_same_curve(make, band):
    model = make()
    full = FRFProblem(model, "odd:3", condensed=False)
    cond = FRFProblem(model, "odd:3", condensed=True)
    for w in (0.4, 0.7, 1.0, 1.3):
        xf = newton(lambda z, w=w: full(z, w)[:2], full.residual.linear_guess(w), 1e-14).x
        xc = newton(lambda z, w=w: cond(z, w)[:2], cond.residual.linear_guess(w), 1e-14).x
        X_full = xf.reshape(full.basis.nb, model.n)
        np.testing.assert_allclose(cond.residual.displacements(xc, w), X_full,
                                   atol=EXACT_RTOL * np.abs(X_full).max())
    a = compute_frf(model, "odd:3", band, condensed=False)
    b = compute_frf(model, "odd:3", band, condensed=True)
    assert a.peak_interior and b.peak_interior
    assert abs(b.peak_amplitude / a.peak_amplitude - 1) < PEAK_RTOL
    assert abs(b.peak_omega / a.peak_omega - 1) < PEAK_OMEGA_RTOL


def test_modal_data_equal_the_matrices():
    mat = chain(5, True)
    lam, phi = sla.eigh(mat.linear.K, mat.linear.M)
    modal = LinearModel(phi=phi, w_r=np.sqrt(lam), c_r=np.diag(phi.T @ mat.linear.C @ phi))
    other = Model(modal, mat.links, mat.forcing, 0)
    a = compute_frf(mat, "odd:3", (1.0, 1.3), condensed=False)
    b = compute_frf(other, "odd:3", (1.0, 1.3))
    assert abs(b.peak_amplitude / a.peak_amplitude - 1) < PEAK_RTOL


def test_condensed_solution_balances_energy_on_the_full_model():
    model = two_dof(False)
    r = compute_frf(model, "odd:5", (0.6, 1.6), condensed=True, refine=False)
    prob = FRFProblem(r.problem.model, "odd:5", condensed=True)  # its links as the curve's
    for x, w in list(zip(r.solutions, r.omega))[::5]:
        e = prob.energy(x, w)
        assert abs(e["W_ext"] - e["W_visc"] - e["W_friction"]) <= ENERGY_RTOL * e["W_ext"]


def solve(model, spec, w):
    prob = FRFProblem(model, spec, condensed=False)
    x = newton(lambda z, w=w: prob(z, w)[:2], prob.residual.linear_guess(w), 1e-14).x
    return x.reshape(prob.basis.nb, model.n)


def test_stuck_element_mean_follows_the_virgin_spring_convention():
    # static load F0 plus a small vibration: the element never slips, so
    # (K + k0) a_0 = F0 by the convention of harmonic_balance.aft
    K, k0, F0 = 1.0, 2.0, 0.01
    model = Model(LinearModel(M=[[1.0]], C=[[0.01]], K=[[K]]),
                  [FrictionLink(jenkins(k0, 1.0), 0)], {0: np.array([F0]), 1: np.array([0.01])})
    X = solve(model, "all:2", 0.7)
    # both to round-off (measured 0, revision a12e5f1)
    assert abs(X[0, 0] / (F0 / (K + k0)) - 1) < EXACT_RTOL
    assert abs(X[3:, 0]).max() < EXACT_RTOL * abs(X).max()  # a linear response has no second harmonic


def test_singular_system_reports_the_frequency_and_keeps_points():
    # free mass (no spring, no damper) whose only support slips freely: harmonic 0
    # has no stiffness at all, so the Jacobian is singular from the start
    model = Model(LinearModel(M=[[1.0]], C=[[0.0]], K=[[0.0]]),
                  [FrictionLink(jenkins(1.0, 0.0), 0)], {1: np.array([0.1])})
    with pytest.raises(FRFError, match="parameter 0.5") as info:
        compute_frf(model, "all:1", (0.5, 1.0))
    assert isinstance(info.value, RuntimeError) and info.value.result is not None


def test_both_resonances_of_the_two_dof_model_are_refined():
    model = two_dof(True)
    r = compute_frf(model, "odd:3", (0.5, 4.0))
    assert len(r.peaks) == 2 and r.peaks[0]["omega"] < 1.5 < r.peaks[1]["omega"]
    assert r.peak_amplitude == max(p["amplitude"] for p in r.peaks)
    prob = FRFProblem(model, "odd:3")
    for p in r.peaks:  # each is a maximum of the curve: lower on both sides
        for dw in (-2e-3, 2e-3):
            w = p["omega"] * (1 + dw)
            x = newton(lambda z, w=w: prob(z, w)[:2], prob.residual.linear_guess(w), 1e-14).x
            assert prob.amplitude(x, w) < p["amplitude"]
