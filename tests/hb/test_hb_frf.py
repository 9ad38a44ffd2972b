"""Forced response of a Jenkins-damped oscillator against analytic references."""
import numpy as np
import pytest
from hbcases import sdof
from jenkins_ref import describing_function
from refcheck import check
from scipy.optimize import brentq, minimize_scalar

from harmonic_balance.frf import FRFProblem, compute_frf
from harmonic_balance.newton import newton

#: H = 1 with exact links against the describing function: both sides are exact, the
#: residual |...| / P - 1 at the curve's points is what Newton and the reference's root
#: finders leave. Measured 8.5e-11 (revision a12e5f1); 100x for the solvers' stopping
#: points on another platform.
DF_RESIDUAL_ATOL = 1e-8
#: Peak against the describing-function peak (brentq to 1e-14 over minimize_scalar to
#: 1e-12): measured 6.8e-12 relative (a12e5f1); 150x, as above.
DF_PEAK_RTOL = 1e-9
#: Growth of the peak's error the validation check lets pass (refcheck.GROWTH is 10):
#: set by the searches' tolerances, within which it may move by more than 10x elsewhere.
SEARCH_GROWTH = 100.0
#: Energy balance with exact links: W_ext = W_visc + W_friction to the Newton tolerance.
#: Measured 3.1e-10 of the input work (a12e5f1); 100x, as above.
ENERGY_RTOL = 3e-8
#: Identities that hold to round-off (stuck, free, scaled systems). Measured 4.8e-15
#: (a12e5f1); 200x for other BLAS builds and thread counts.
EXACT_RTOL = 1e-12
#: Two evaluations of the same H = 1 peak (peak_amplitude and peak_amplitude_h1):
#: measured 1.4e-16 relative (a12e5f1); round-off, 700x.
SAME_PEAK_RTOL = 1e-13

M, K, C, KT, FS, P = 1.0, 1.0, 0.01, 1.0, 0.05, 0.05


def df_residual(w, a):
    """|(k - m w^2) a + a1 + i(-c w a + b1)| - P (references.md)."""
    a1, b1 = describing_function(KT, FS, a)
    return abs(complex((K - M * w**2) * a + a1, -C * w * a + b1)) - P


def df_peak():
    """Largest amplitude with a solution: where min over w of df_residual reaches 0."""
    def gap(a):
        return minimize_scalar(lambda w: df_residual(w, a), bounds=(0.9, 1.3),
                               method="bounded", options={"xatol": 1e-12}).fun
    return brentq(gap, 0.1, 0.3, xtol=1e-14)


@pytest.fixture(scope="module")
def h1_curve():
    return compute_frf(sdof(M, K, C, KT, FS, P), 1, (0.9, 1.3))


def test_h1_reproduces_the_jenkins_describing_function(h1_curve):
    r = h1_curve
    assert r.status == "complete" and r.omega[0] == 0.9 and r.omega[-1] == 1.3
    err = [df_residual(w, a) / P for w, a in zip(r.omega, r.amplitude_h1)]
    check("H = 1 FRF residual |...| / P - 1 of the Jenkins oscillator, every point", err, 0.0, atol=DF_RESIDUAL_ATOL,
          source="describing function (references.md)")
    # the sweep goes through resonance: from stuck to well into slip and back
    assert r.amplitude.max() > 3 * FS / KT and r.amplitude[0] < 0.3 * r.amplitude.max()


def test_h1_peak_matches_the_describing_function_peak(h1_curve):
    assert h1_curve.peak_interior
    check("H = 1 peak amplitude [m], Jenkins oscillator m = k = kt = 1, c = 0.01, fs = P = 0.05",
          h1_curve.peak_amplitude, df_peak(), rtol=DF_PEAK_RTOL, source="describing-function peak",
          growth=SEARCH_GROWTH)
    assert abs(h1_curve.peak_amplitude / h1_curve.peak_amplitude_h1 - 1) < SAME_PEAK_RTOL  # H = 1
    assert h1_curve.peak_amplitude >= h1_curve.amplitude.max()


def test_energy_balances_at_every_solution_point():
    model = sdof(M, K, C, KT, FS, P)
    r = compute_frf(model, "odd:5", (0.9, 1.3), refine=False)
    prob = r.problem  # the links as the curve evaluated them (exact)
    for x, w in zip(r.solutions, r.omega):
        e = prob.energy(x, w)
        assert e["W_ext"] > 0
        assert abs(e["W_ext"] - e["W_visc"] - e["W_friction"]) <= ENERGY_RTOL * e["W_ext"]


def solve_at(model, spec, omegas):
    prob = FRFProblem(model, spec)
    out = []
    x = prob.residual.linear_guess(omegas[0])
    for w in omegas:
        x = newton(lambda z, w=w: prob(z, w)[:2], x, 1e-12 * P).x
        out.append(prob.amplitude(x, w))
    return np.array(out)


def test_infinite_friction_gives_the_stuck_linear_system():
    om = np.linspace(1.2, 1.6, 5)
    amp = solve_at(sdof(M, K, C, KT, 1e9, P), "all:3", om)
    lin = np.abs(P / (K + KT - M * om**2 + 1j * C * om))
    np.testing.assert_allclose(amp, lin, rtol=EXACT_RTOL)


def test_zero_friction_gives_the_free_linear_system():
    om = np.linspace(0.9, 1.1, 5)
    amp = solve_at(sdof(M, K, C, KT, 0.0, P), "all:3", om)
    lin = np.abs(P / (K - M * om**2 + 1j * C * om))
    np.testing.assert_allclose(amp, lin, rtol=EXACT_RTOL)


def test_scaling_force_and_slip_strength_scales_the_response():
    om = np.array([1.0, 1.08, 1.2])
    a = solve_at(sdof(M, K, C, KT, FS, P), "odd:5", om)
    b = solve_at(sdof(M, K, C, KT, 3.7 * FS, 3.7 * P), "odd:5", om)
    np.testing.assert_allclose(b, 3.7 * a, rtol=EXACT_RTOL)


def test_a_coarse_time_grid_is_flagged_as_aliased():
    fine = compute_frf(sdof(M, K, C, KT, FS, P), 1, (1.0, 1.2), aft="sampled")
    coarse = compute_frf(sdof(M, K, C, KT, FS, P), 1, (1.0, 1.2), n_t=16, aft="sampled")
    assert fine.status == "complete" and fine.alias_ratio < 1e-3
    assert "warning" in coarse.status and coarse.alias_ratio > 1e-2


#: Peak of the exact links on a 16-point scan against the default 256: the scan only
#: brackets the extrema of u (refined by Newton), so only round-off differs. Measured
#: 6.4e-15 (a12e5f1); 150x for other BLAS builds and thread counts.
SCAN_RTOL = 1e-12


def test_exact_links_do_not_depend_on_the_scan_grid():
    """Exact links (the default) have no sampling: a 16-point scan of u' gives the
    256-point scan's peak, no aliasing warning (alias ratio 0)."""
    fine = compute_frf(sdof(M, K, C, KT, FS, P), 1, (1.0, 1.2))
    coarse = compute_frf(sdof(M, K, C, KT, FS, P), 1, (1.0, 1.2), n_t=16)
    assert coarse.status == "complete" and coarse.alias_ratio == 0.0
    assert abs(coarse.peak_amplitude / fine.peak_amplitude - 1) < SCAN_RTOL
    assert abs(coarse.peak_omega / fine.peak_omega - 1) < SCAN_RTOL


def test_tiny_force_refines_the_stuck_linear_peak():
    # the element never slips: the peak is the stuck system's, P / (c w) at sqrt(2)
    r = compute_frf(sdof(M, K, C, KT, FS, 1e-4), "odd:3", (1.2, 1.6))
    w_n = np.sqrt((K + KT) / M)
    lin = 1e-4 / (C * w_n)  # |P / Z| at w_n; the damped maximum differs by O(zeta^2) ~ 1e-5
    assert r.peak_interior and abs(r.peak_omega / w_n - 1) < 1e-4
    assert abs(r.peak_amplitude / lin - 1) < 1e-4


#: Random curves compared with scipy's peak finder (the definition peak_indices follows).
PEAK_FINDER_TRIALS = 2000


def test_peak_indices_agree_with_scipy_find_peaks():
    """Same peaks and prominence rule as scipy.signal.find_peaks (plateaus, ties, edges)
    on random curves, integer-valued ones included (plateaus and equal bases)."""
    from scipy.signal import find_peaks

    from harmonic_balance.peaks import peak_indices

    rng = np.random.default_rng(20261122)
    for trial in range(PEAK_FINDER_TRIALS):
        n = int(rng.integers(3, 60))
        a = rng.integers(0, 6, n).astype(float) if trial % 2 else rng.normal(size=n)
        p = float(rng.uniform(0.0, 2.0))
        idx, props = find_peaks(a, prominence=0.0)
        want = [int(i) for i, q in zip(idx, props["prominences"]) if q > p]
        assert peak_indices(a, p) == want, (a, p)


#: The coarse start and the start at the full set solve the same equations to
#: |R| < TOL_REL times the problem's reference: their solutions agree to that over the
#: Jacobian's scale; measured 3e-13 relative (chain5 at H = 9); 1e-8 for the conditioning
#: of a link near its slip onset.
START_RTOL = 1e-8


def test_coarse_start_is_the_start_found_at_the_full_harmonics():
    from harmonic_balance import bench_models as bm
    from harmonic_balance.frf import START_H, TOL_REL, _coarse_start
    from harmonic_balance.start import homotopy_start

    case = bm.chain5()
    prob, w0 = FRFProblem(case.model(), tuple(range(START_H + 5))), case.band[0]
    tol = TOL_REL * prob.reference(w0)
    full, _ = homotopy_start(prob, w0, tol)
    coarse, info = _coarse_start(prob, w0, tol)
    assert np.linalg.norm(coarse - full) <= START_RTOL * np.linalg.norm(full)
    assert f"H <= {START_H}" in info["method"]
    assert _coarse_start(FRFProblem(case.model(), tuple(range(START_H + 1))), w0, tol) is None
