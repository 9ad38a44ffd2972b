"""Den Hartog's rigid-Coulomb + viscous oracle, and the stiff-contact limit of the HB."""
import numpy as np
import pytest
from refcheck import check
from scipy.integrate import solve_ivp

from harmonic_balance.denhartog import den_hartog
from harmonic_balance.frf import TOL_REL, FRFProblem, compute_frf
from harmonic_balance.model import sdof_model
from harmonic_balance.start import homotopy_start
from harmonic_balance.timeint import steady_curve

#: The reference single-DOF case: m = k = 1, c = 0.04, slip force 0.5, forcing 1.
M, C, K, FS, P = 1.0, 0.04, 1.0, 0.5, 1.0


@pytest.mark.parametrize("omega, kind", [(0.5, "stops"), (1.0, "continuous"), (2.0, "continuous")])
def test_half_period_is_an_antisymmetric_solution_of_the_ode(omega, kind):
    """The oracle's half period, integrated by solve_ivp from (-A, 0) (sliding forward),
    ends at (A, 0) (antisymmetry x(t + T/2) = -x(t)), and the kind is the expected one."""
    d = den_hartog(M, C, K, FS, P, omega)
    assert d.kind == kind

    def slip(t, z):
        return [z[1], P * np.cos(omega * t + d.phi) - FS - C * z[1] - K * z[0]]

    s = solve_ivp(slip, (0.0, d.t_slip), [-d.amplitude, 0.0], rtol=1e-12, atol=1e-14)
    # 2e-12 measured: solve_ivp's own tolerance
    np.testing.assert_allclose(s.y[:, -1], [d.amplitude, 0.0], atol=1e-9 * d.amplitude)


@pytest.mark.slow
def test_regularised_time_integration_agrees_with_the_oracle():
    """An independent steady state: sgn(v) ~ tanh(v / 1e-4) integrated 300 periods
    from rest (measured 1.6e-4 relative at omega = 2, the regularisation's error)."""
    w, eps = 2.0, 1e-4

    def rhs(t, z):
        return [z[1], P * np.cos(w * t) - FS * np.tanh(z[1] / eps) - C * z[1] - K * z[0]]

    T = 2 * np.pi / w
    s = solve_ivp(rhs, (0, 300 * T), [0.0, 0.0], method="LSODA", rtol=1e-9, atol=1e-12,
                  dense_output=True)
    x = s.sol(np.linspace(295 * T, 300 * T, 4000))[0]
    check("amplitude [m] of the regularised (tanh) Coulomb oscillator, time integration, 2 rad/s",
          np.abs(x).max(), den_hartog(M, C, K, FS, P, w).amplitude, rtol=5e-4, source="Den Hartog 1931")


def test_below_the_slip_force_the_mass_never_moves():
    assert den_hartog(M, C, K, 1.2, P, 1.0).kind == "stuck"


@pytest.mark.slow
def test_stiff_jenkins_at_resonance_agrees_with_den_hartog():
    """Contact stiffness 1e3 k, H = 21, at resonance: measured 1.1e-4 relative.

    Away from resonance the elastic (Jenkins) steady state approaches the rigid one
    only like kt^-1/2 (time integration at omega = 2: 9 % at 1e3 k, 3 % at 1e4 k,
    0.9 % at 1e5 k: the stuck mode sqrt(kt / m) rings after each reversal), so the
    required 1 % at 1e3 k holds at resonance, not over the whole band.
    """
    r = compute_frf(sdof_model(M, K, C, 1e3, FS, P), 21, (0.98, 1.02), refine=False)
    a = np.interp(1.0, r.omega, r.amplitude)
    check("HB amplitude [m], Jenkins 1e3 k, H = 21, at resonance (1 rad/s)", a,
          den_hartog(M, C, K, FS, P, 1.0).amplitude, rtol=2e-4, source="Den Hartog 1931 (rigid Coulomb)")


@pytest.mark.slow
def test_stiff_jenkins_off_resonance_hb_is_the_elastic_model_not_the_rigid_one():
    """1e3 k, H = 21, omega = 1.5 and 2 rad/s: the HB agrees with the time integration
    of the SAME elastic Jenkins model (measured 4.7e-3 and 3.5e-3; 8e-5 at H = 51 and
    omega = 2: the rest is the truncation of the stuck mode's ringing at
    sqrt(kt / m) / omega ~ 16-21 harmonics), while both differ from Den Hartog's rigid
    Coulomb solution by 5-10 % (measured HB 5.7 %, 9.6 %; TI 5.2 %, 9.2 %): the required
    1 % at 1e3 k cannot hold off resonance for the elastic model itself (TI at 1e5 k:
    within 0.95 % of Den Hartog over 0.5-2 rad/s, README.md at revision c58d443)."""
    omegas = np.array([1.5, 2.0])
    model = sdof_model(M, K, C, 1e3, FS, P)
    a_ti, _, err, _ = steady_curve(model, omegas, 512)
    assert np.all(err < 1e-3)  # time-step error estimate (measured 4.9e-4, 1.4e-4)
    prob = FRFProblem(model, 21)
    for w, ti in zip(omegas, a_ti):
        x, _ = homotopy_start(prob, w, TOL_REL * prob.reference(w))
        hb = prob.amplitude(x, w)
        dh = den_hartog(M, C, K, FS, P, w).amplitude
        check(f"HB amplitude [m], Jenkins 1e3 k, H = 21, {w:g} rad/s", hb, ti, rtol=7e-3,
              kind="self-consistency", source="time integration of the same model (harmonic_balance.timeint)")
        assert hb / dh - 1 > 0.04 and ti / dh - 1 > 0.04
