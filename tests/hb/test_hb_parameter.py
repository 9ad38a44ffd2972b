"""Continuation over parameters other than frequency (harmonic_balance.parameter)."""
import numpy as np
import pytest
from hbcases import two_dof

from harmonic_balance.frf import compute_frf
from harmonic_balance.model import sdof_model
from harmonic_balance.parameter import forcing_level, slip_scale
from harmonic_balance.parameter_curve import parameter_curve

#: A parameter curve's end point against the FRF solved directly with that parameter,
#: and the stuck part's linearity in the level: the same equations solved to the Newton
#: tolerance from different starts. Measured 2.2e-16 and 1.3e-15 (revision a12e5f1;
#: 1e-14 at an earlier one); 1e-12 for other BLAS builds and thread counts.
SAME_SOLUTION_RTOL = 1e-12


@pytest.mark.slow  # > 1 s: outside the `-m "not slow"` inner loop
def test_forcing_level_curve_ends_on_the_frf_solution():
    """lam = 0.1 -> 2 at omega = 1 on the stiff (30 k) Jenkins oscillator: the end point is
    the FRF's solution at forcing 2 (started there by its own homotopy); stuck below the
    slip onset, the amplitude is linear in the level."""
    model = sdof_model(1, 1, 0.04, 30, 0.5, 1.0)
    c = parameter_curve(forcing_level(model), "odd:7", (0.1, 2.0), 1.0, affine=True)
    assert c.status == "complete" and c.lam[-1] == 2.0 and all(c.stable)
    r = compute_frf(sdof_model(1, 1, 0.04, 30, 0.5, 2.0), "odd:7", (1.0, 1.01), refine=False)
    assert abs(c.amplitude[-1] / r.amplitude[0] - 1) < SAME_SOLUTION_RTOL
    stuck = c.lam < 0.4  # slip force 0.5 not reached at omega = 1
    np.testing.assert_allclose(c.amplitude[stuck] / c.lam[stuck], c.amplitude[0] / c.lam[0],
                               rtol=SAME_SOLUTION_RTOL)


def test_slip_scale_curve_matches_the_model_built_with_that_slip_force():
    m = two_dof(True)
    c = parameter_curve(slip_scale(m), "odd:3", (0.1, 3.0), 1.1)
    assert c.status == "complete" and c.lam[-1] == 3.0
    r = compute_frf(two_dof(True, fs=0.04 * 3.0), "odd:3", (1.1, 1.11), refine=False)
    assert abs(c.amplitude[-1] / r.amplitude[0] - 1) < SAME_SOLUTION_RTOL


def test_contact_stiffness_family_shares_the_first_residual_operators():
    """ParameterProblem builds one residual and swaps the links' elements for the others
    (Residual.with_elements): the same numbers as a residual built from scratch."""
    from harmonic_balance.fourier import FourierBasis
    from harmonic_balance.parameter import ParameterProblem, contact_stiffness_scale
    from harmonic_balance.residual import make_residual

    model = sdof_model(1, 1, 0.04, 1e3, 0.5, 1.0)
    at = contact_stiffness_scale(model)
    pp = ParameterProblem(at, "odd:5", 0.8)
    x = make_residual(model, pp.basis).linear_guess(0.8) * 30
    for lam in (-3.0, -1.5, 0.0):
        fresh = make_residual(at(lam), FourierBasis(pp.basis.harmonics))
        R, J, _ = pp.residual(lam)(x, 0.8)
        R0, J0, _ = fresh(x, 0.8)
        assert np.array_equal(R, R0) and np.array_equal(J, J0)
    assert pp.residual(-1.5)._K is pp.residual(0.0)._K   # shared, not rebuilt
    with pytest.raises(ValueError, match="more than its links"):
        pp.residual(0.0).with_elements(sdof_model(1, 2, 0.04, 1e3, 0.5, 1.0))


@pytest.mark.parametrize("condensed", [False, True])
def test_exact_stiffness_derivative_matches_the_central_difference(condensed):
    """StiffnessScale.dR_dlam (ln 10 x the links' Jacobian on their own displacement,
    from F(q; s k) = F(s q; k)) against the central difference of the residual in lam,
    on a 2-DOF model (one link between the DOFs, one to ground), full and condensed.
    Away from AFT kinks the difference is exact to O(h^2) + round-off / h ~ 1e-9."""
    from harmonic_balance.parameter import ParameterProblem, contact_stiffness_scale

    model = two_dof(True)
    at = contact_stiffness_scale(model)
    pp = ParameterProblem(at, "odd:5", 1.05, condensed=condensed)
    x = pp.residual(-0.5).linear_guess(1.05) * 40
    for lam in (-2.0, -0.5, 0.0):
        R, J, exact = pp(x, lam)
        h = 1e-6
        fd = (pp.residual(lam + h)(x, 1.05, jac=False) - pp.residual(lam - h)(x, 1.05, jac=False)) / (2 * h)
        assert np.linalg.norm(exact - fd) < 1e-6 * np.linalg.norm(fd)
        assert np.linalg.norm(fd) > 0
