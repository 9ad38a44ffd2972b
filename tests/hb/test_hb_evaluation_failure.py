"""A residual that cannot be evaluated at some x (the friction element's periodic loop
not closing, ``IwanNotConvergedError``) is a failed Newton iteration: a continuation
step is shortened, and a failure that persists ends the curve with a message naming it."""
from __future__ import annotations

import numpy as np
import pytest

from fmu_src.element import IwanNotConvergedError
from harmonic_balance import bench_models as bm
from harmonic_balance.continuation import ContinuationError, continuation
from harmonic_balance.frf import FRFError, compute_frf
from harmonic_balance.newton import NewtonError, newton

#: Newton's tolerance on |R| for the scalar branch x = lam^2.
TOL = 1e-12
#: Distance from the branch beyond which the test residual refuses to evaluate: far
#: below the predictor's error of a long step (~ ds^2 on a parabola), so the default
#: steps fail and only shortened ones succeed.
FAIL_BEYOND = 1e-3
#: Points of the branch must satisfy x = lam^2 to the corrector's tolerance (|R| <= TOL).
BRANCH_TOL = 1e-10


def _parabola(fail_beyond=FAIL_BEYOND, fail_above=np.inf):
    """R = x - lam^2, raising the element's error where |R| > fail_beyond or lam > fail_above."""
    calls = {"failed": 0}

    def fun(x, lam):
        r = x[0] - lam**2
        if abs(r) > fail_beyond or lam > fail_above:
            calls["failed"] += 1
            raise IwanNotConvergedError("test element: periodic loop did not close")
        return np.array([r]), np.array([[1.0]]), np.array([-2.0 * lam])
    return fun, calls


def test_newton_reports_an_evaluation_failure_as_a_newton_error():
    def fun(x):
        raise IwanNotConvergedError("test element: periodic loop did not close")
    with pytest.raises(NewtonError, match="cannot be evaluated"):
        newton(fun, np.zeros(1), TOL)


def test_continuation_shortens_steps_where_the_residual_cannot_be_evaluated():
    fun, calls = _parabola()
    br = continuation(fun, np.array([1.0]), 1.0, 3.0, TOL, ds=0.2, ds_max=0.5)
    lam, x = np.array(br.lam), np.array(br.x)[:, 0]
    assert calls["failed"] > 0  # the long steps did fail
    assert lam[-1] == pytest.approx(3.0)
    assert np.max(np.abs(x - lam**2)) <= BRANCH_TOL


def test_persistent_evaluation_failure_stops_the_curve_with_its_reason():
    fun, _ = _parabola(fail_beyond=np.inf, fail_above=2.0)
    with pytest.raises(ContinuationError, match="cannot be evaluated") as info:
        continuation(fun, np.array([1.0]), 1.0, 3.0, TOL, ds=0.2, ds_max=0.5)
    lam = np.array(info.value.branch.lam)
    assert 1.9 < lam.max() <= 2.0  # traced up to where it fails


#: Periods the contact point's loop may be marched: the element's default (400), at
#: which loops near 0.56 rad/s do not close (bench_models.CONTACT_POINT_PERIODS).
FEW_PERIODS = 400
#: Share of the band a curve at FEW_PERIODS traces at least: its first loops that do not
#: close lie near 0.56 rad/s, 5 % into the band (0.5-1.6 rad/s).
PASSED_SHARE = 0.1
#: Highest harmonic of these curves: loops that do not close in FEW_PERIODS come from the
#: slider's slow drift in the time march, which a curve at H = 3 meets as one at the
#: case's H = 7 does, for a small fraction of the cost (n_t and the Jacobians grow with H).
HARMONICS = 3


def test_contact_point_curve_passes_loops_that_do_not_close(monkeypatch):
    """Steps whose loops do not close are shortened: the curve goes on past them, to the
    band's end or to a stretch where every nearby state fails, which then ends it with the
    element's reason (which of the two depends on where the continuation's points fall)."""
    monkeypatch.setattr(bm, "CONTACT_POINT_PERIODS", FEW_PERIODS)
    failed = []
    init = IwanNotConvergedError.__init__

    def counted(self, *args):   # each loop that did not close
        failed.append(args)
        init(self, *args)
    monkeypatch.setattr(IwanNotConvergedError, "__init__", counted)
    case = bm.contact_point()
    lo, hi = case.band
    try:
        r = compute_frf(case.model(), HARMONICS, case.band, stability="off")
    except FRFError as err:
        assert "periodic loop did not close" in str(err)
        reached = float(str(err).split("stopped at parameter ")[1].split()[0])
        assert reached > lo + PASSED_SHARE * (hi - lo)  # past the first failing loops
    else:
        assert r.omega[0] == pytest.approx(lo) and r.omega[-1] == pytest.approx(hi)
    assert failed  # some loops did not close: the curve went past them


def test_contact_point_that_never_closes_its_loop_fails_with_the_reason(monkeypatch):
    monkeypatch.setattr(bm, "CONTACT_POINT_PERIODS", 1)
    case = bm.contact_point()
    with pytest.raises(FRFError, match="periodic loop did not close"):
        compute_frf(case.model(), HARMONICS, case.band, stability="off")
