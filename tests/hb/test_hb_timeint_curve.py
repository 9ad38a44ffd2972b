"""The vectorised time-integration reference (all frequencies at once, batched element).

It must be the frequency-by-frequency reference (:func:`march`) computed another
way (closed-form step operators, one ``step_batch`` call per element per step,
frequencies leaving as they settle), and agree with the converged harmonic balance.
"""
import numpy as np
import pytest
from hbcases import jenkins, sdof, two_dof

from harmonic_balance.frf import compute_frf
from harmonic_balance.timeint import march, march_curve, steady_curve

#: Converged HB (H = 7) against the time integration at the peak: H truncation and the
#: march's time step, deterministic. Measured 1.1e-4 (revision a12e5f1); 9x, as
#: test_hb_timeint.TI_RTOL.
TI_RTOL = 1e-3
#: Beside the peak the HB value is interpolated between the curve's points: measured
#: 4.6e-3 at 0.98 peak frequency (a12e5f1), the interpolation's error.
TI_SIDE_RTOL = 5e-3
#: march and march_curve run the same scheme; they differ by the round-off of an
#: LU solve against a precomputed inverse, amplified over a few hundred periods.
#: Measured 3.3e-13 (a12e5f1); 90x for other BLAS builds and thread counts.
SAME_SCHEME_RTOL = 3e-11
#: Steady-state tolerance of the marches (extrapolated change per period).
SS_TOL = 1e-7


@pytest.mark.slow  # > 2 s: outside the `-m "not slow"` inner loop
def test_curve_march_equals_march_frequency_by_frequency_two_dof():
    model = two_dof()                       # one element between DOFs, one to ground
    ws = np.array([0.85, 1.25])             # settle at different periods
    c = march_curve(model, ws, 128, tol=SS_TOL)
    assert c.converged.all() and c.periods[0] != c.periods[1]
    for i, w in enumerate(ws):
        s = march(model, w, 128, tol=SS_TOL)
        assert s.periods == c.periods[i] and s.steps_per_period == c.steps_per_period
        np.testing.assert_allclose(c.x_last[i], s.x_last, rtol=0,
                                   atol=SAME_SCHEME_RTOL * np.abs(s.x_last).max())


@pytest.mark.slow  # > 1 s: outside the `-m "not slow"` inner loop
def test_curve_march_agrees_with_converged_harmonic_balance_at_the_peak():
    model = sdof()
    r = compute_frf(model, "odd:7", (0.9, 1.3))
    ws = r.peak_omega * np.array([0.98, 1.0, 1.02])
    amp, h1, step_err, c = steady_curve(model, ws, 256, tol=SS_TOL)
    assert np.all(step_err < 1e-3)          # the reference itself is converged in dt
    assert abs(amp[1] / r.peak_amplitude - 1) < TI_RTOL
    assert amp[1] > max(amp[0], amp[2])     # the HB peak is the time-integration peak
    # the same frequencies on the HB curve (interpolated between its points)
    order = np.argsort(r.omega)
    hb = np.interp(ws[[0, 2]], np.asarray(r.omega)[order], np.asarray(r.amplitude)[order])
    np.testing.assert_allclose(amp[[0, 2]], hb, rtol=TI_SIDE_RTOL)


def test_element_without_batch_entry_gives_the_same_curve(monkeypatch):
    # the python oracle (tests/hb/jenkins_ref.py) has no batch entry: one step() per state
    monkeypatch.setenv("HB_TEST_ORACLE", "1")
    oracle = sdof()
    assert not hasattr(oracle.links[0].element, "batch_stepper")
    monkeypatch.delenv("HB_TEST_ORACLE")
    c_core = sdof()
    ws = np.array([1.0, 1.2])
    a = march_curve(oracle, ws, 64, tol=1e-5)
    b = march_curve(c_core, ws, 64, tol=1e-5)
    assert np.array_equal(a.periods, b.periods)
    np.testing.assert_allclose(a.amplitude, b.amplitude, rtol=SAME_SCHEME_RTOL)


@pytest.mark.parametrize("omegas", [[], [1.0, -1.0], [np.nan]])
def test_bad_frequencies_are_refused(omegas):
    with pytest.raises(ValueError, match="omegas"):
        march_curve(sdof(), omegas)


def test_jenkins_helper_is_the_c_core_by_default():
    assert hasattr(jenkins(1.0, 0.05), "batch_stepper")
