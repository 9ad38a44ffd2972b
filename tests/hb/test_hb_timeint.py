"""Harmonic balance against a time integration of the same model to steady state."""
import pytest
from hbcases import sdof, two_dof
from refcheck import check

from harmonic_balance.frf import compute_frf
from harmonic_balance.timeint import march, steady_amplitude

#: Converged HB against the time integration: H truncation and the march's time-step
#: error, both deterministic. Measured 1.1e-4 (Jenkins oscillator, H = 7) and 3.6e-5
#: (2-DOF, H = 5) (revision a12e5f1); 1e-3, 9x the larger.
TI_RTOL = 1e-3
#: Steady-state tolerance of the march (extrapolated change per period).
SS_TOL = 1e-8


@pytest.fixture(scope="module")
def peaks():
    model = sdof()
    return model, {H: compute_frf(model, f"odd:{H}", (0.9, 1.3)) for H in (3, 5, 7)}


def test_peak_converges_with_the_number_of_harmonics(peaks):
    _, r = peaks
    # the change shrinks as H grows (response harmonics fall off like 1/h^4)
    d35 = abs(r[5].peak_amplitude - r[3].peak_amplitude)
    d57 = abs(r[7].peak_amplitude - r[5].peak_amplitude)
    assert d57 < d35 and d57 < 1e-3 * r[7].peak_amplitude


@pytest.mark.slow  # > 2 s: outside the `-m "not slow"` inner loop
def test_converged_hb_peak_agrees_with_time_integration(peaks):
    model, r = peaks
    amp, _, step_err, ss = steady_amplitude(model, r[7].peak_omega, 256, tol=SS_TOL)
    assert ss.converged and step_err < 1e-3  # the reference itself is converged in dt
    check("HB peak amplitude [m], Jenkins oscillator, H = odd:7", r[7].peak_amplitude, amp, rtol=TI_RTOL,
          kind="self-consistency", source="time integration to steady state (harmonic_balance.timeint)")


@pytest.mark.slow  # > 1 s: outside the `-m "not slow"` inner loop
def test_two_dof_hb_agrees_with_time_integration_at_the_peak():
    # at the peak the friction damping is largest, so the march settles fastest
    model = two_dof()
    r = compute_frf(model, "odd:5", (0.6, 1.6))
    s = march(model, r.peak_omega, 256, tol=SS_TOL)
    assert s.converged
    check("HB peak amplitude [m], 2-DOF Jenkins model, H = odd:5", r.peak_amplitude, s.amplitude, rtol=TI_RTOL,
          kind="self-consistency", source="time integration to steady state (harmonic_balance.timeint)")
