"""Contact elements in harmonic balance against time integration with the exact C element.

Both sides use the same law (the C element, N = k_n max(p, 0)); they share nothing
else: the time integration (``timeint.march``) steps the element sample by sample from
rest, the harmonic balance uses the periodic AFT loop. The HB solutions are reached
by Newton with a homotopy in the forcing level from the stuck linear guess.
"""
import numpy as np
import pytest
from refcheck import check

from fmu_src.element import IwanElement
from harmonic_balance.contact import ContactElement
from harmonic_balance.fourier import FourierBasis
from harmonic_balance.kinematics import Kinematics
from harmonic_balance.linear import LinearModel
from harmonic_balance.model import Model
from harmonic_balance.newton import newton
from harmonic_balance.residual import FullResidual
from harmonic_balance.timeint import march

pytestmark = pytest.mark.slow

#: Newton tolerance on |R| (forces of order 1 N).
NEWTON_TOL = 1e-11
#: Time-integration steps per period. Its step error (256 vs 512 steps) was measured
#: at 2.2e-5 (bouncing peak) and 1.2e-4 (2D contact energy); the finer run is used.
STEPS = 512


def solve_hb(make_model, P, omega, H, levels=20):
    """HB solution at forcing level P, continued from P / levels (stuck linear guess)."""
    b = FourierBasis(H)
    x = None
    for Pi in np.linspace(P / levels, P, levels):
        res = FullResidual(make_model(Pi), b)
        x = res.linear_guess(omega) if x is None else x
        x = newton(lambda z, r=res: r(z, omega)[:2], x, NEWTON_TOL).x
    return res, b, x


def bouncing_mass(P, m=1.0, kn=1.0, c=0.1, weight=1.0):
    """Mass on a penalty floor (p = -y) under its weight and P cos(omega t); no other spring."""
    floor = ContactElement(Kinematics([0], [[-1.0]]), kn, name="floor")
    lin = LinearModel(M=[[m]], C=[[c]], K=[[0.0]])
    return Model(lin, [floor], {0: np.array([-weight]), 1: np.array([P])})


#: HB (H = 15) against time integration, bouncing mass: measured 8.1e-6 (peak |y|),
#: 1.9e-5 (first harmonic), 8.2e-6 absolute (mean, static deflection 1); the requirement
#: asks for 0.5 %: tolerances 1.5x measured.
BOUNCE_PEAK_RTOL = 1.2e-5
BOUNCE_H1_RTOL = 2.8e-5
BOUNCE_MEAN_ATOL = 1.2e-5


def test_bouncing_mass_with_lift_off_matches_time_integration():
    omega, P = 1.2, 0.8
    res, b, x = solve_hb(bouncing_mass, P, omega, 15)
    X = x.reshape(b.nb, 1)
    lift = res.evaluate(x, omega)[0].f[:, 0] == 0.0
    assert 0.2 < lift.mean() < 0.4          # lifts off over ~28 % of the period
    assert abs(X[0, 0] + 1.0) > 0.05         # the mean moves with the lift-off
    ti = march(bouncing_mass(P), omega, STEPS)
    assert ti.converged
    c = np.fft.rfft(ti.x_last) / ti.steps_per_period
    ti_ref = "time integration of the same model (harmonic_balance.timeint)"
    check("bouncing mass with lift-off, peak |x| [m], H = 15", b.peak_abs(X[:, 0]), ti.amplitude,
          rtol=BOUNCE_PEAK_RTOL, kind="self-consistency", source=ti_ref)
    check("bouncing mass with lift-off, first harmonic [m], H = 15", b.magnitude(X, 1)[0], 2 * abs(c[1]),
          rtol=BOUNCE_H1_RTOL, kind="self-consistency", source=ti_ref)
    assert abs(X[0, 0] - c[0].real) <= BOUNCE_MEAN_ATOL


def plane_contact_model(P, psi, dN=0.5, N0=1.0, kx=1.0, kt=2.0, kn=10.0, mu=0.3, c=0.1, iwan=False):
    """Mass (x, y) on a Jenkins contact (s = x, p = -y), spring k_x on x.

    y is pressed by N0 plus dN cos(omega t + psi); x is driven by P cos(omega t).
    ``iwan``: three sliders of total stiffness kt and strength mu N0 at N_ref = N0
    instead of the Jenkins element (the curve's shape scaled by N / N_ref).
    """
    kin = Kinematics.contact([0, 1], [0.0, 1.0], [1.0, 0.0], np.eye(2))
    if iwan:
        sliders = IwanElement.from_sliders(kt * np.array([0.5, 0.3, 0.2]), mu * N0 * np.array([0.2, 0.3, 0.5]),
                                           N_ref=N0)
        el = ContactElement(kin, kn, sliders, name="contact")
    else:
        el = ContactElement.jenkins(kin, kn, kt, mu, name="contact")
    lin = LinearModel(M=np.eye(2), C=c * np.eye(2), K=np.diag([kx, 0.0]))
    return Model(lin, [el], {0: np.array([0.0, -N0]),
                             1: np.array([P, -dN * np.exp(1j * psi)])})


#: Friction energy per cycle, HB (H = 15) against time integration: measured 2.9e-5
#: (in phase), 2.4e-5 (quarter period out of phase), 3.0e-5 (Iwan, in phase);
#: tolerance 1.5x the largest.
#: (A normal load opposite in phase, psi = pi, is psi = 0 by symmetry: test_hb_forces.)
ENERGY_RTOL = 4.5e-5


@pytest.mark.parametrize("psi,iwan", [(0.0, False), (np.pi / 2, False), (0.0, True)],
                         ids=["in_phase", "out_of_phase", "iwan_in_phase"])
def test_contact_energy_per_cycle_with_varying_normal_load_matches_time_integration(psi, iwan):
    omega, P = 1.0, 0.5
    make = lambda Pi: plane_contact_model(Pi, psi, iwan=iwan)  # noqa: E731
    res, b, x = solve_hb(make, P, omega, 15, levels=10)
    loop = res.evaluate(x, omega)[0]
    N = loop.f[:, 1]
    assert np.ptp(N) > 0.5 * N.mean()        # the normal load varies strongly
    assert np.any(np.abs(loop.f[:, 0]) >= 0.3 * N * (1 - 1e-12))  # and the contact slips
    ti = march(make(P), omega, STEPS)
    assert ti.converged
    (W_ti,) = ti.W_elements
    assert abs(loop.W - W_ti) <= ENERGY_RTOL * W_ti
