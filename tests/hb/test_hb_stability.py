"""Hill stability along forced-response curves (harmonic_balance.stability)."""
import numpy as np

from harmonic_balance.aft import FrictionLink
from harmonic_balance.cubic import CubicSpring
from harmonic_balance.frf import compute_frf
from harmonic_balance.linear import LinearModel
from harmonic_balance.model import Model, sdof_model


def duffing():
    """x'' + 0.02 x' + x + 0.1 x^3 = 0.1 cos(omega t): hardening, folds near 1.08 and 1.40."""
    return Model(LinearModel(M=[[1.0]], C=[[0.02]], K=[[1.0]]), [FrictionLink(CubicSpring(0.1), 0)],
                 {1: np.array([0.1])})


def test_duffing_middle_branch_is_found_and_flagged_unstable(tmp_path):
    r = compute_frf(duffing(), "odd:5", (0.5, 2.5))
    assert r.status == "complete"
    om, st = np.asarray(r.omega), np.asarray(r.stable)
    back = np.flatnonzero(np.diff(om) < 0)  # the middle branch: omega runs backwards
    assert back.size > 5
    # unstable exactly between the two folds (the fold points themselves may go either way)
    mid = np.arange(back[0] + 1, back[-1] + 1)
    assert not st[mid].any()
    outside = np.setdiff1d(np.arange(om.size), np.arange(back[0], back[-1] + 2))
    assert st[outside].all()
    from harmonic_balance.plots import plot_frf

    assert len(plot_frf(r, tmp_path)) == 3  # dashed middle branch drawn


def test_friction_curve_is_stable_everywhere():
    r = compute_frf(sdof_model(1, 1, 0.04, 30, 0.5, 1.0), "odd:7", (0.5, 2.0))
    assert r.stable is not None and all(r.stable)
