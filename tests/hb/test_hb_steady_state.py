"""Which steady state: the HB peak against time integrations from rest and from the HB state."""
import numpy as np
import pytest

from harmonic_balance.aft import FrictionLink
from harmonic_balance.frf import compute_frf
from harmonic_balance.linear import LinearModel
from harmonic_balance.model import Model, jenkins_element, sdof_model
from harmonic_balance.steady_state import SAME_STATE_TOL, check_peak, summary_lines

#: The stuck single-DOF oscillator is linear at its peak, so H = 7 is exact there; the
#: time integration from the HB state then keeps it to the central differences' step
#: error at 512 steps a period (measured 7e-6 relative at c = 0.04).
HB_STATE_KEPT = 1e-4
#: Static load [N] that holds the slider stuck in the HB (mean spring force 0.6 N, peak
#: 0.74 N under the 1 N slip force) while its sudden application from rest overshoots
#: to 1.2 N of spring force and slips it: the start from rest settles at another mean.
STATIC_LOAD, SLIP_FORCE = 1.2, 1.0


def _preloaded_sdof() -> Model:
    """m = k = 1, c = 0.1, a Jenkins slider (k_t = 1) to the ground, a static load plus
    0.02 cos(omega t): at the stuck resonance sqrt(2) the slider never slips."""
    lin = LinearModel(M=np.eye(1), C=0.1 * np.eye(1), K=np.eye(1))
    link = FrictionLink(jenkins_element(1.0, SLIP_FORCE), 0, None, "slider")
    return Model(lin, [link], {0: np.array([STATIC_LOAD + 0j]), 1: np.array([0.02 + 0j])}, 0)


@pytest.mark.slow
def test_start_from_rest_settles_at_another_stuck_mean_than_the_hb_convention():
    r = compute_frf(_preloaded_sdof(), 7, (1.2, 1.6), truncation_check=False,
                    steady_state_check=True)
    rec = r.extra["steady_state"]
    assert r.extra["stuck_links"] == ["slider"]
    assert abs(rec["hb_mean"] - STATIC_LOAD / 2) < 1e-9   # the convention: k_t u mean, K + k_t = 2
    # the HB state, sliders carrying its period's past, stays where the HB put it ...
    assert abs(rec["hb_state_drift"]) < HB_STATE_KEPT
    assert abs(rec["mean_from_hb_state"] - rec["hb_mean"]) < HB_STATE_KEPT
    # ... and the start from rest, having slipped once, ends on another mean
    assert rec["states_differ"] and rec["states_rel"] > SAME_STATE_TOL
    assert rec["mean_from_rest"] > rec["hb_mean"] + 0.05
    assert r.extra["steady_state_warning"].startswith("warning:")
    assert any("two steady states" in line for line in summary_lines(rec))
    assert r.summary()["steady_state"]["states_differ"] is True


def test_no_warning_where_rest_and_the_hb_state_settle_alike():
    model = sdof_model(1.0, 1.0, 0.04, 1.0, 0.5, 1.0)
    r = compute_frf(model, 7, (0.9, 1.2), truncation_check=False, steady_state_check=True)
    rec = r.extra["steady_state"]
    assert r.extra["stuck_links"] == []   # the slider slips at the peak
    assert not rec["states_differ"] and rec["states_rel"] < SAME_STATE_TOL
    assert r.extra["steady_state_warning"] is None
    # the slipping slider's mean is the dynamics', not a convention: both near zero
    assert abs(rec["mean_from_rest"]) < 1e-3 * rec["from_rest"]


def test_without_the_check_only_the_stuck_links_are_reported():
    r = compute_frf(_preloaded_sdof(), 3, (1.2, 1.6), truncation_check=False)
    assert r.extra["stuck_links"] == ["slider"] and "steady_state" not in r.extra
    s = r.summary()
    assert s["stuck_links"] == ["slider"] and "steady_state" not in s


def test_check_needs_matrices():
    class NoMatrices:
        peak_omega, peak_solution, peak_amplitude = 1.0, np.zeros(3), 1.0

        class problem:
            class model:
                class linear:
                    K = M = None

    assert "note" in check_peak(NoMatrices())


def test_time_integration_from_the_hb_state_stays_on_it_with_the_sliders_past():
    """Two periods from the HB state (H = 15: 3e-6 from converged on this oscillator) stay
    within HB_STATE_KEPT of its peak when the slider has been run through the HB period
    first; a virgin slider at the same displacement carries the wrong force until its
    first reversal (measured 6.5e-4 off after two periods)."""
    from harmonic_balance.steady_state import hb_period
    from harmonic_balance.timeint import march

    model = sdof_model(1.0, 1.0, 0.04, 1.0, 0.5, 1.0)
    r = compute_frf(model, 15, (0.9, 1.2), truncation_check=False, stability="off")
    w = r.peak_omega
    xs, v0 = hb_period(r.problem.basis, r.problem.residual.displacements(r.peak_solution, w), w, 2048)
    kept = march(model, w, 512, max_periods=2, tol=0.0, x0=xs[0], v0=v0, history=np.vstack([xs, xs]))
    virgin = march(model, w, 512, max_periods=2, tol=0.0, x0=xs[0], v0=v0)
    assert abs(kept.amplitude / r.peak_amplitude - 1) < HB_STATE_KEPT
    assert abs(virgin.amplitude / r.peak_amplitude - 1) > HB_STATE_KEPT   # the past matters


#: Central differences with step 1e-7 on a loop that stays stuck (no switch crossed):
#: round-off ~1e-8 of the entries (as tests/hb/test_hb_jacobian.py).
FD_RTOL = 1e-6


def _preloaded_past_the_limit() -> Model:
    """As :func:`_preloaded_sdof` with c = 0.04 and a 1.5 N static load: the virgin stuck
    line k_t u would reach 1.1 N of spring force at the stuck resonance, past the 1 N
    slip force."""
    lin = LinearModel(M=np.eye(1), C=0.04 * np.eye(1), K=np.eye(1))
    link = FrictionLink(jenkins_element(1.0, SLIP_FORCE), 0, None, "slider")
    return Model(lin, [link], {0: np.array([1.5 + 0j]), 1: np.array([0.02 + 0j])}, 0)


@pytest.mark.slow
def test_stuck_convention_stays_within_the_slip_limit_under_a_static_load():
    """The stuck slider is shifted by the least amount that keeps it within its limit
    (the C core's loop): its force never exceeds the slip force, and the time integration
    started from that state keeps it (an inadmissible k_t u line drifted 9 %)."""
    r = compute_frf(_preloaded_past_the_limit(), 7, (1.3, 1.5), truncation_check=False,
                    stability="off", steady_state_check=True)
    u, F, W = r.problem.residual.link_samples(r.peak_solution)[0]
    assert W == 0.0 and np.abs(F).max() <= SLIP_FORCE * (1 + 1e-12)
    assert abs(F.max() - SLIP_FORCE) < 1e-12 * SLIP_FORCE   # shifted: touches the limit
    rec = r.extra["steady_state"]
    assert rec["stuck_links"] == ["slider"] and abs(rec["hb_state_drift"]) < HB_STATE_KEPT
    assert rec["states_differ"]   # from rest, the load's sudden start slips it elsewhere


def test_shifted_stuck_jacobian_matches_finite_differences():
    from harmonic_balance.fourier import FourierBasis
    from harmonic_balance.residual import FullResidual

    r = compute_frf(_preloaded_past_the_limit(), 3, (1.3, 1.5), truncation_check=False,
                    stability="off", refine=False)
    res = FullResidual(r.problem.model, FourierBasis("all:3"))
    i = int(np.argmax(r.amplitude))
    x, w = r.solutions[i], float(r.omega[i])
    _, F, _ = res.link_samples(x)[0]
    assert abs(F.max() - SLIP_FORCE) < 1e-12   # a shifted stuck loop: its mean hangs on max u
    _, J, _ = res(x, w)
    Jfd = np.empty_like(J)
    for j in range(x.size):
        e = np.zeros_like(x)
        e[j] = 1e-7
        Jfd[:, j] = (res(x + e, w, jac=False) - res(x - e, w, jac=False)) / 2e-7
    assert np.abs(J - Jfd).max() <= FD_RTOL * np.abs(J).max()


def test_cli_check_steady_state_reports_both_time_integrations(capsys):
    import json

    from damper.cli import main

    argv = ["frf", "--model", "sdof", "--harmonics", "5", "--omega", "0.9", "1.2", "--stability", "off"]
    assert main(argv + ["--check-steady-state", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    rec = out["steady_state"]
    assert rec["states_differ"] is False and out["steady_state_warning"] is None
    assert rec["from_rest"] > 0 and rec["from_hb_state"] > 0 and out["stuck_links"] == []
    assert main(argv + ["--check-steady-state"]) == 0
    assert "steady state (time integration at the peak): from rest" in capsys.readouterr().out
