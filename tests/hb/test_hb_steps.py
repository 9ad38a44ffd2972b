"""Steps sized by the curve's shape, peaks that are never stepped over, and complete
curves that never end in failure (harmonic_balance.continuation, frf, peaks)."""
import numpy as np
import pytest

from harmonic_balance.aft import FrictionLink
from harmonic_balance.frf import compute_frf
from harmonic_balance.linear import LinearModel
from harmonic_balance.model import Model, jenkins_element, sdof_model

#: Two refined peaks of the same discrete curve agree to the refinement's frequency
#: tolerance (1e-6), so their amplitudes to about its square. Measured 1.5e-13 (kink,
#: down against up) and 2.0e-12 (finer curve tolerance) (revision a12e5f1); 50x.
SAME_PEAK = 1e-10


def chain3(force, knl):
    """NLvib's 3-mass friction chain: m = [1, 1, 1], grounded chain of unit springs,
    C = 0.02 K, force on mass 2 (the response), Jenkins links ground-mass 1 and
    mass 1-mass 2 of stiffness knl and slip force 1."""
    K = np.array([[2.0, -1.0, 0.0], [-1.0, 2.0, -1.0], [0.0, -1.0, 2.0]])
    links = [FrictionLink(jenkins_element(knl, 1.0), 0, None, "ground"),
             FrictionLink(jenkins_element(knl, 1.0), 0, 1, "between")]
    return Model(LinearModel(M=np.eye(3), C=0.02 * K, K=K), links,
                 {1: np.array([0.0, force, 0.0])}, response_dof=1)


def test_a_small_resonance_on_a_flat_curve_is_not_stepped_over():
    """Force 0.5, knl 2000: the links nearly stick, the curve is flat to 1 % but for the
    third mass's resonance near 1.395 rad/s, 0.6 % high: steps of 0.1 scaled arclength
    with no limit in frequency cross the curve in 14 points and step over it (peak 0.58 %
    low, 5 % off in frequency). Both directions and a finer tolerance find the same
    refined peak."""
    peaks = [compute_frf(chain3(0.5, 2000.0), 7, rng, stability=False, **kw)
             for rng, kw in (((0.5, 2.0), {}), ((2.0, 0.5), {}), ((0.5, 2.0), {"tolerance": 1e-3}))]
    assert all(r.peak_interior and r.extra["peak_refined"] for r in peaks)
    assert 1.39 < peaks[0].peak_omega < 1.40
    for r in peaks[1:]:
        assert abs(r.peak_amplitude / peaks[0].peak_amplitude - 1) < SAME_PEAK


def test_a_kink_where_a_second_slip_pair_appears_is_crossed_without_restart():
    """Force 1, knl 20, swept down: at 1.02978 rad/s the second link gains a second pair
    of slip phases per cycle, the branch turns by more than 90 deg in scaled variables
    and the pseudo-arclength plane misses it (without the fixed-frequency corrector and
    the kink rule: a stall, a restart by homotopy and a gap, whatever the AFT grid). It
    is crossed in the same curve, on the default grid, with the up-sweep's peak."""
    down = compute_frf(chain3(1.0, 20.0), 7, (2.0, 0.5), stability=False)
    up = compute_frf(chain3(1.0, 20.0), 7, (0.5, 2.0), stability=False)
    for r in (down, up):
        assert r.status == "complete" and r.extra["gaps"] == [] and r.extra["grid_doublings"] == 0
    assert abs(down.peak_amplitude / up.peak_amplitude - 1) < SAME_PEAK


@pytest.mark.parametrize("kt", [2e3, 5e3, 1e4])
def test_stiff_links_complete_with_a_refined_peak(kt):
    """k_t = 2e3 ... 1e4 k, c = 0.04, slip force 0.5, F = 1, H = 7, 0.9 -> 1.1: the curve
    completed but its peak refinement failed (exit 3); exact links refine it."""
    r = compute_frf(sdof_model(1, 1, 0.04, kt, 0.5, 1.0), 7, (0.9, 1.1), stability=False)
    assert r.status == "complete" and r.extra["peak_refined"] and r.peak_interior


def test_a_failed_peak_refinement_keeps_the_highest_point_and_says_so(monkeypatch):
    """Whatever makes the refinement fail, a complete curve is returned: its highest point
    as the peak, ``peak_refined`` False and a warning in the status; a sampled curve's
    refinement is retried with exact links first."""
    import harmonic_balance.peaks as peaks

    real = peaks.refine_max

    def failing(prob, *args, **kw):
        if all(getattr(el, "exact", False) for el in prob.model.links):
            return real(prob, *args, **kw)
        raise RuntimeError("corrector failed")
    monkeypatch.setattr(peaks, "refine_max", failing)
    model = sdof_model(1, 1, 0.04, 1.0, 0.5, 1.0)
    r = compute_frf(model, 3, (0.8, 1.3), stability=False, aft="sampled")
    assert r.extra["peak_refined"] and r.peak_interior   # by the exact retry
    monkeypatch.setattr(peaks, "refine_max", lambda *a, **k: (_ for _ in ()).throw(RuntimeError("no")))
    r = compute_frf(model, 3, (0.8, 1.3), stability=False)
    assert r.status.startswith("complete; warning: peak refinement failed")
    assert r.extra["peak_refined"] is False and not r.peak_interior
    assert r.peak_amplitude == r.amplitude.max() and r.summary()["peak_refined"] is False
