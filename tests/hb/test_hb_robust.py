"""Convergence map (quick) of the single-DOF Jenkins FRF: the cases that converge.

The full map is examples/bench_hb_robust.py. Here: contact stiffness 1e-3 ... 1e6 k,
slip force 0.5 of the forcing, sweeps that start below, at and above resonance,
H = 3: each curve completes over the whole requested range with no tuning and no gaps.
"""
import json

import numpy as np
import pytest

from damper.cli import main
from harmonic_balance.frf import compute_frf, stiff_samples
from harmonic_balance.model import sdof_model


@pytest.mark.parametrize("kt", [1e-3, 1.0, 30.0, 1e3, 1e4, 1e5, 1e6])
@pytest.mark.parametrize("start", [0.5, 1.0, 2.0])
def test_sdof_jenkins_curve_completes_from_any_start(kt, start):
    end = 2.0 if start < 2.0 else 0.5
    r = compute_frf(sdof_model(1, 1, 0.04, kt, 0.5, 1.0), "odd:3", (start, end), refine=False)
    assert r.status.startswith("complete") and r.omega[-1] == end
    # no gaps: the fixed-parameter corrector fallback removed them at 1e4 k, the finer AFT
    # grid for links > 1e4 k (frf.stiff_samples) at 1e5 and 1e6 k
    assert r.extra["gaps"] == []


def test_stiff_samples_grow_like_the_square_root_of_the_stiffness_ratio():
    """Stick episodes last ~ kt^-1/2 of the period: default grid up to 1e4 k, then
    512 sqrt(ratio / 1e4) samples rounded up to a power of two (2048 at 1e5, 8192 at
    1e6 k), whatever H (at least H's default)."""
    for H in (3, 15):
        n = {kt: stiff_samples(sdof_model(1, 1, 0.04, kt, 0.5, 1.0), H) for kt in (1e4, 1e5, 1e6)}
        assert n == {1e4: 0, 1e5: 2048, 1e6: 8192}
    assert stiff_samples(sdof_model(1, 1, 0.04, 1e5, 0.5, 1.0), 51) == 2048  # default 2048


@pytest.mark.parametrize("kt, fs, H", [(1e-3, 1e-3, 1), (1.0, 0.5, 7), (1e3, 0.5, 1)])
@pytest.mark.parametrize("start", [0.5, 1.0, 2.0])
def test_nearly_undamped_peak_completes_from_any_start(kt, fs, H, start):
    """c = 1e-4 (peak ~1e4 P / k, 1e-4 rad/s wide): these cases circled the peak until
    the 3000-point limit or, started at 1 rad/s, left the range (the corrector jumped
    between the flanks); measured after the fix 180-700 points, no gaps."""
    end = 2.0 if start < 2.0 else 0.5
    r = compute_frf(sdof_model(1, 1, 1e-4, kt, fs, 1.0), H, (start, end), refine=False,
                    stability=False, max_points=3000)
    # (the status may carry the AFT aliasing warning of the stick-slip peak)
    assert r.status.startswith("complete") and r.extra["gaps"] == [] and r.omega[-1] == end
    assert r.points < 1500
    assert np.all(np.sign(end - start) * np.diff(r.omega) > 0)


def test_grazing_slip_is_crossed_by_the_exact_aft_or_a_finer_grid(monkeypatch):
    """Slip force = forcing, 10 k, c = 1e-4, H = 3: above 1 rad/s the link's force only
    just exceeds f_s at the turning points, so the slip episodes of a sampled loop span a
    handful of samples and its corrector stalls (measured: gaps near 1.46 and 1.49 rad/s
    on 32 samples, none on 64; with a fixed largest step of 0.1 it stalled at 1.1066 rad/s
    on 256-1024 samples). The exact links (the default) have no samples to miss:
    complete on the default grid. Sampled from a 32-sample grid, compute_frf traces the
    stalled curve again on doubled grids; with the grid fixed by the caller there is no
    doubling: the gaps stay (and are reported)."""
    import harmonic_balance.frf as frf

    model = sdof_model(1, 1, 1e-4, 10.0, 1.0, 1.0)
    r = compute_frf(model, 3, (0.5, 2.0), refine=False, stability=False)
    assert r.status.startswith("complete") and r.extra["gaps"] == [] and r.omega[-1] == 2.0
    assert r.extra["aft"] == "exact" and r.n_t == 256 and r.extra["grid_doublings"] == 0
    monkeypatch.setattr(frf, "default_samples", lambda H: 32)
    r = compute_frf(model, 3, (0.5, 2.0), refine=False, stability=False, aft="sampled")
    assert r.status.startswith("complete") and r.extra["gaps"] == [] and r.extra["aft"] == "sampled"
    assert r.extra["grid_doublings"] >= 1 and r.n_t == 32 * 2 ** r.extra["grid_doublings"]
    r0 = compute_frf(model, 3, (0.5, 2.0), n_t=32, refine=False, stability=False, aft="sampled")
    assert r0.extra["gaps"] and r0.extra["grid_doublings"] == 0 and "restart" in r0.status


@pytest.mark.slow
def test_first_point_at_1e6_k_inside_the_slipping_resonance():
    """1e6 k, slip force 0.5 P, c = 1e-4, H = 7, at omega = 1 (amplitude 3634): every
    start stalled at |R| = 6e-10 ... 9e-10 for a tolerance of 1e-10 (the stiff link's
    round-off, |dx| / |x| ~ 8e-14); Newton now stops at its round-off floor."""
    m = sdof_model(1, 1, 1e-4, 1e6, 0.5, 1.0)
    r = compute_frf(m, 7, (1.0, 1.1), refine=False, stability=False)
    assert r.status.startswith("complete") and r.extra["gaps"] == [] and r.amplitude[0] > 3000
    # energy balance of the converged start: viscous + friction work = input, to the
    # round-off floor where Newton stops (|R| ~ 1e-9 of the force at 1e6 k); measured
    # 1.6e-16 relative (revision a12e5f1), bounded by 10x that floor
    e = r.problem.energy(r.solutions[0], 1.0)
    assert abs(e["W_visc"] + e["W_friction"] - e["W_ext"]) < 1e-8 * e["W_ext"]


@pytest.mark.slow
def test_reference_case_stiffness_1e4_no_gaps():
    """The reference case at 1e4 k (H = 15): in the stick-slip band near 0.5 rad/s the
    pseudo-arclength corrector cycles on AFT kinks (41 gaps without a fallback); the
    fixed-parameter corrector fallback solves it (measured: 292 points, 0 gaps, ~6 s alone)."""
    r = compute_frf(sdof_model(1, 1, 0.04, 1e4, 0.5, 1.0), 15, (0.5, 2.0), refine=False,
                    stability=False)
    assert r.status == "complete" and r.extra["gaps"] == [] and r.omega[-1] == 2.0


@pytest.mark.slow
def test_stiffness_1e6_h7_no_gaps():
    """1e6 k, H = 7, from 0.5 rad/s: the stick-slip band is traced without gaps (measured:
    190 points, ~9 s); the link is evaluated exactly (frf.exact_links), so H's default 256
    samples only scan u' for its extrema."""
    r = compute_frf(sdof_model(1, 1, 0.04, 1e6, 0.5, 1.0), 7, (0.5, 2.0), refine=False,
                    stability=False)
    assert r.status == "complete" and r.extra["gaps"] == [] and r.n_t == 256
    assert r.problem.model.links[0].exact


def test_contact_stiffness_30_h15_completes_from_its_first_point(capsys):
    """30 k, H = 15, through the CLI: the first point is found and the curve completes,
    with its stability."""
    code = main(["frf", "--model", "sdof", "--mass", "1", "--stiffness", "1", "--damping", "0.04",
                 "--contact-stiffness", "30", "--slip-force", "0.5", "--force", "1",
                 "--harmonics", "15", "--omega", "0.5", "2", "--json"])
    out = json.loads(capsys.readouterr().out)
    assert code == 0 and out["status"] == "complete" and out["stable"] is not None


def test_failure_text_output_is_a_message_not_a_traceback(capsys):
    """A run that stops before its first point: exit 3, 'none' numbers, no TypeError."""
    code = main(["frf", "--model", "sdof", "--damping", "0.0", "--stiffness", "0",
                 "--contact-stiffness", "1", "--slip-force", "0", "--harmonics", "all:1",
                 "--omega", "0.5", "1.0"])
    cap = capsys.readouterr()
    assert code == 3 and "none" in cap.out and "failed" in cap.err


def test_stiff_start_on_a_coarse_grid_is_the_fine_grids_solution(monkeypatch):
    """1e6 k, H = 15, 4096 samples, from 0.5 rad/s (the stiffness homotopy's case): the
    homotopy runs on H's default 512 samples and Newton finishes on 4096 from there
    (measured: 1.0 s -> 0.5 s, 3-4 Newton iterations); the answer is the one the fine
    grid's own homotopy gives, to the solver tolerance."""
    import harmonic_balance.start as start
    from harmonic_balance.frf import TOL_REL, FRFProblem

    m = sdof_model(1, 1, 0.04, 1e6, 0.5, 1.0)
    fine = FRFProblem(m, 15, 4096)
    tol = TOL_REL * fine.reference(0.5)
    x, info = start.homotopy_start(fine, 0.5, tol)
    assert info["method"] == "stiffness homotopy on 512 samples, then Newton"
    assert np.linalg.norm(fine(x, 0.5)[0]) <= tol
    monkeypatch.setattr(start, "COARSE_FACTOR", 1e9)   # the fine grid's homotopy
    ref, info_ref = start.homotopy_start(fine, 0.5, tol)
    assert info_ref["method"] == "stiffness homotopy"
    # both Newton-converged to |R| <= TOL_REL of the reference force: measured 4.1e-14
    # (revision a12e5f1); TOL_REL is the solver's guarantee
    assert abs(fine.amplitude(x, 0.5) / fine.amplitude(ref, 0.5) - 1) < TOL_REL


@pytest.mark.slow
def test_grazing_slip_at_h51_completes_with_exact_links():
    """The H = 51 map's only failures with the sampled AFT (1e4 k, f_s = P, starts at
    1 rad/s: 'no solution at fixed parameter 2', Newton's 30 iterations on the grazing
    kinks): complete with the exact links, the default (measured ~9 s, 96 points)."""
    r = compute_frf(sdof_model(1, 1, 1e-4, 1e4, 1.0, 1.0), 51, (1.0, 2.0), refine=False,
                    stability=False)
    assert r.status.startswith("complete") and r.extra["gaps"] == [] and r.omega[-1] == 2.0
    assert r.extra["aft"] == "exact"


@pytest.mark.slow
def test_homotopy_lands_from_its_last_point_when_the_interpolated_guess_stalls():
    """100 k, f_s = P, c = 1e-4, H = 51 at 2 rad/s (grazing slip: k_t u = 1.0025 f_s at the
    turning points): the stiffness homotopy reached 10^-0.005 of the stiffness and the
    landing on 1 from the interpolated guess stalled at |R| = 3e-4 (the H = 51 map's last
    failure); from the last accepted point Newton converges (measured 24 iterations)."""
    from harmonic_balance.frf import TOL_REL, FRFProblem
    from harmonic_balance.start import homotopy_start

    p = FRFProblem(sdof_model(1, 1, 1e-4, 100.0, 1.0, 1.0), 51)
    x, info = homotopy_start(p, 2.0, TOL_REL * p.reference(2.0))
    assert info["method"] == "stiffness homotopy"
    assert np.linalg.norm(p(x, 2.0)[0]) <= TOL_REL * p.reference(2.0)
    assert abs(p.amplitude(x, 2.0) - 0.01003) < 1e-5     # k_t u ~ f_s: grazing
