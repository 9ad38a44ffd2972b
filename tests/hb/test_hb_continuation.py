"""Newton and arc-length continuation on plain residuals (no mechanics)."""
import numpy as np
import pytest

from harmonic_balance.continuation import ContinuationError, continuation, refine_max
from harmonic_balance.newton import NewtonError, newton

TOL = 1e-12


def s_curve(x, lam):
    """lam = x^3 - 3x: two turning points, at (x, lam) = (-1, 2) and (1, -2)."""
    return np.array([x[0] ** 3 - 3 * x[0] - lam]), np.array([[3 * x[0] ** 2 - 3]]), np.array([-1.0])


#: Curve accuracy of the turning-point test: the folds are sampled to ~1e-3 of the range.
FOLD_TOL = 1e-3


def test_continuation_passes_two_turning_points():
    br = continuation(s_curve, np.array([-2.2]), -4.0, 4.0, TOL, tolerance=FOLD_TOL)
    x, lam = np.array(br.x)[:, 0], np.array(br.lam)
    assert br.status == "complete" and lam[-1] == 4.0
    np.testing.assert_allclose(x**3 - 3 * x, lam, atol=1e-10)
    assert x[-1] > 2.0  # reached the upper sheet through both folds
    assert np.all(np.diff(x) > 0)  # followed the branch, did not jump across the S
    assert lam[x < 0].max() > 1.99 and lam[(x > 0) & (x < 1.5)].min() < -1.99  # both folds


def test_continuation_failure_keeps_the_points_and_names_the_parameter():
    def fold(x, lam):  # x^2 = lam: from lam = 1 toward -1 the branch turns back at 0
        return np.array([x[0] ** 2 - lam]), np.array([[2 * x[0]]]), np.array([-1.0])

    with pytest.raises(ContinuationError, match="parameter") as info:
        continuation(fold, np.array([1.0]), 1.0, -1.0, TOL, tolerance=FOLD_TOL)
    br = info.value.branch
    assert len(br.lam) > 5 and min(br.lam) < 0.01
    assert isinstance(info.value, RuntimeError)


def test_refine_max_locates_the_peak_to_tolerance():
    def hump(x, lam):  # x = 1 - (lam - 0.3)^2 + 0.1 lam^3
        r = x[0] - (1 - (lam - 0.3) ** 2 + 0.1 * lam**3)
        return np.array([r]), np.array([[1.0]]), np.array([2 * (lam - 0.3) - 0.3 * lam**2])

    br = continuation(hump, np.array([0.0]), -1.0, 1.0, TOL, ds_max=0.2)
    i = int(np.argmax([x[0] for x in br.x]))
    x, lam, amp, _ = refine_max(hump, br, i, lambda x, l: x[0], TOL, 1e-9)
    # d/dlam: -2 (lam - 0.3) + 0.3 lam^2 = 0
    lam_true = (2 - np.sqrt(4 - 4 * 0.3 * 0.6)) / 0.6
    assert abs(lam - lam_true) < 1e-8
    assert abs(amp - (1 - (lam_true - 0.3) ** 2 + 0.1 * lam_true**3)) < 2 * TOL  # corrector tol


def test_newton_reports_why_it_failed():
    with pytest.raises(NewtonError, match="no decrease") as info:
        newton(lambda x: (x**2 + 1.0, np.diag(2 * x)), np.array([0.5]), TOL)
    # x^2 + 1 has no real root: Newton and then Levenberg-Marquardt end in the minimum of
    # |R| at x = 0, where |R| = 1, and say after how many iterations
    e = info.value
    assert isinstance(e, RuntimeError) and 1 <= e.iterations <= 30 and f"after {e.iterations} iterations" in str(e)
    assert e.residual == pytest.approx(1.0, abs=1e-9) and abs(e.x[0]) < 1e-4
    with pytest.raises(NewtonError, match="singular"):
        newton(lambda x: (x**2 + 1.0, np.diag(2 * x)), np.array([0.0]), TOL)


def test_newton_converges_quadratically():
    res = newton(lambda x: (np.array([np.exp(x[0]) - 2.0]), np.array([[np.exp(x[0])]])),
                 np.array([0.0]), 1e-14)
    assert abs(res.x[0] - np.log(2)) < 1e-14 and res.iterations <= 6


def _oscillator(c):
    """x'' + c x' + x = cos(lam t) at H = 1, x = a cos + b sin: the response traces a
    circle of diameter 1 / c through the origin within ~c of lam = 1 (its Nyquist plot)."""
    def fun(x, lam):
        a, b = x
        d = 1.0 - lam**2
        R = np.array([d * a + c * lam * b - 1.0, d * b - c * lam * a])
        J = np.array([[d, c * lam], [-c * lam, d]])
        return R, J, np.array([-2 * lam * a + c * b, -2 * lam * b - c * a])
    return fun


@pytest.mark.parametrize("lam0, lam1", [(0.5, 2.0), (1.0, 2.0), (2.0, 0.5)])
def test_continuation_crosses_a_resonance_of_q_10000(lam0, lam1):
    """c = 1e-4: the peak is 1e-4 of the range wide and 1e4 high. With the x scale
    fixed at the largest RMS met, the two flanks near the origin lay ~1e-3 apart in
    scaled units and the corrector jumped between them (the branch circled the peak
    until the point limit, or, started at 1, left the range after 31 points); the x
    scale following the current point and the orientation test keep lam monotone
    (measured 20-30 points per decade of amplitude)."""
    fun = _oscillator(1e-4)
    br = continuation(fun, np.array([1.0, 0.0]), lam0, lam1, TOL, ds_max=0.1, max_points=3000)
    lam = np.array(br.lam)
    assert br.status == "complete" and lam[-1] == lam1
    assert np.all(np.sign(lam1 - lam0) * np.diff(lam) > 0)  # no turning back
    assert len(lam) < 600  # measured 180-360 (the 'at' start has one flank)
    amp = np.hypot(*np.array(br.x).T)
    assert amp.max() > 0.9e4  # the top of the peak (1 / c = 1e4) is on the curve


def test_newton_stops_at_the_round_off_floor():
    """A stiff residual with an absolute noise floor above tol (as a 1e6 k link's
    F = k0 (u - z)): converged once the step is below STEP_RTOL of |x|, not an error."""
    def fun(x):
        R = 1e6 * (x - 3.0) + 1e-9 * np.sin(1e12 * x)  # noise 1e-9 > tol
        return R, np.array([[1e6]])
    res = newton(fun, np.array([1.0]), 1e-12)
    assert abs(res.x[0] - 3.0) < 1e-14 * 3 + 2e-15 and res.iterations <= 4


#: brent_min's tolerance in x in these tests.
BRENT_XTOL = 1e-10


def test_brent_min_finds_the_minimum_to_an_absolute_tolerance():
    """A smooth minimum (x = 0.3 of (x - 0.3)^2 + 0.1 (x - 0.3)^4) next to the start, one at
    a bound, and an interval where f is inf (points to avoid) on one side."""
    from harmonic_balance.continuation import brent_min

    x, f, n = brent_min(lambda x: (x - 0.3) ** 2 + 0.1 * (x - 0.3) ** 4, -1.0, 1.0, BRENT_XTOL,
                        start=0.0)
    assert abs(x - 0.3) < 2 * BRENT_XTOL and f < 1e-18 and n < 40
    x, _, _ = brent_min(lambda x: x, -1.0, 1.0, BRENT_XTOL)
    assert x < -1.0 + 3 * BRENT_XTOL
    x, _, _ = brent_min(lambda x: np.inf if x > 0.5 else (x - 0.45) ** 2, -1.0, 1.0, BRENT_XTOL,
                        start=0.0)
    assert abs(x - 0.45) < 2 * BRENT_XTOL
