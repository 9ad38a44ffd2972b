"""The UPD curves by continuation (solve.frf): values on the grid interpolated on the
branch agree with Newton solves at the grid points, a folded curve is followed, the start
does not depend on the way it is reached."""
import numpy as np
import pytest

from harmonic_balance.bladed_disk import solve
from harmonic_balance.bladed_disk.hb import SectorHB
from harmonic_balance.bladed_disk.solve import TOL_REL

#: Energy imbalance at the peak: the Newton stopping tolerance |R| < solve.TOL_REL max(F0, CF)
#: bounds it (the solver's guarantee); measured <= 2.4e-15 over these tests (revision a12e5f1).
ENERGY_IMBALANCE = TOL_REL

#: Grid values against Newton at the grid points: each is a branch point or corrected by
#: Newton to the solve's tolerance from its interpolated value, so the same equilibrium
#: (measured 4e-15 at H = 3 over 430-470 Hz, 3e-14 on a stuck flank; the interpolation
#: alone was 4.3e-4 and 3.0e-3 off).
GRID_RTOL = 1e-10
#: Two refinements of the same discrete curve's peak: to the frequency tolerance
#: (PEAK_XTOL = 1e-6), so in amplitude to its square and the correctors' 1e-10.
#: Measured 7.3e-9 (revision a12e5f1).
PEAK_RTOL = 1e-8


def test_grid_values_agree_with_newton_at_the_grid_points(sector):
    om = 2 * np.pi * np.linspace(430.0, 470.0, 25)
    c = solve.frf(SectorHB(sector, 3), om)
    assert c.extra["method"].startswith("continuation") and "grid" in c.extra["method"]
    hb = SectorHB(sector, 3)
    ref = np.array([hb.amplitude_h1(x) for x in solve.sweep(hb, om)])
    assert np.abs(c.amplitude / ref - 1).max() < GRID_RTOL
    assert c.omega[0] == om[0] and c.omega[-1] == om[-1] and c.extra["peak_refined"]
    assert c.peak_amplitude >= c.amplitude.max()
    # the peak does not depend on the grid the curve is reported on
    c2 = solve.frf(SectorHB(sector, 3), np.linspace(om[0], om[-1], 7))
    assert abs(c2.peak_amplitude / c.peak_amplitude - 1) < PEAK_RTOL


def test_grid_values_on_a_stuck_flank_are_the_equilibria_at_the_grid_points(sector):
    """CF 1e6 N (every contact stuck: a lightly damped linear ring) over 480-560 Hz on 5
    points: the continuation's steps there span a grid spacing and the interpolated value
    at 520 Hz was 0.45 % low (H 3) before the grid values were corrected."""
    om = 2 * np.pi * np.linspace(480.0, 560.0, 5)
    c = solve.frf(SectorHB(sector, 3, cf=1e6), om)
    hb = SectorHB(sector, 3, cf=1e6)
    ref = np.array([hb.amplitude_h1(x) for x in solve.sweep(hb, om)])
    assert np.abs(c.amplitude / ref - 1).max() < GRID_RTOL
    assert "corrected by Newton" in c.extra["method"] and "warning" not in c.extra


def test_a_start_reached_by_the_force_level_equals_the_curve_s(sector):
    """CF 20 N, H = 3: Newton from the stuck guess converges at 400 Hz, not at 430 Hz,
    where the start is a continuation in the EO force level; the curve traced from
    400 Hz ends on the same solution."""
    w0, w1 = 2 * np.pi * 400.0, 2 * np.pi * 430.0
    hb = SectorHB(sector, 3, cf=20.0)
    x = solve.start_point(hb, w1)
    c = solve.frf(SectorHB(sector, 3, cf=20.0), np.array([w0, w1]), refine=False)
    # two Newton solutions of the same equations: within the stopping tolerance
    # (solve.TOL_REL); measured 3.5e-15 (revision a12e5f1)
    assert np.linalg.norm(c.x[-1] - x) < TOL_REL * np.linalg.norm(x)


def test_folded_curve_of_the_craig_bampton_blade_is_followed(tmp_path, capsys):
    """CB blade of examples/craig_bampton_blade.py at CF = 250 N, F0 = 10 N, H = 3: a grid
    sweep stops at the fold (431.4 Hz up, 416.3 Hz down); the continuation passes it and
    reports the branch's own points. Measured: 102 points (10494 with the step control of
    a fixed largest step), peak 422.85 Hz 0.782 mm; at 424 Hz the branch holds 0.25 mm
    (lower branch) and 0.78 mm (upper) as byo found by direct Newton solves."""
    import importlib.util
    import json
    from pathlib import Path

    from damper.cli import main

    path = Path(__file__).resolve().parents[2] / "examples" / "craig_bampton_blade.py"
    spec = importlib.util.spec_from_file_location("craig_bampton_blade", path)
    ex = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(ex)
    blade, _ = ex.reduce_blade(ex.fe_blade(), 6)
    toml = ex.write_case(tmp_path, blade, (1.0, 2.0))
    *_, lo, hi = ex.linear_band(toml)
    toml = ex.write_case(tmp_path, blade, (lo, hi))
    assert main(["upd", "frf", "--config", str(toml), "--harmonics", "3", "--cf", "250",
                 "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert "the branch folds" in out["method"]
    f, a = np.array(out["frequency_hz"]), np.array(out["amplitude"])
    assert out["branch_points"] == f.size   # a folded curve is reported at its own points
    # a fold: the branch crosses 424 Hz three times, on a low and a high amplitude
    cross = np.nonzero(np.diff(np.sign(f - 424.0)))[0]
    assert len(cross) >= 3
    amps = a[cross]
    assert amps.max() > 2.5 * amps.min()
    assert out["peak_frequency_hz"] == pytest.approx(422.85, abs=0.01)
    assert abs(out["energy_per_cycle_at_peak"]["imbalance"]) < ENERGY_IMBALANCE
