"""Smoke run of examples/bench_hb_robust.py (the full run is by hand)."""
import pytest


@pytest.mark.slow  # > 1 s: outside the `-m "not slow"` inner loop
def test_robustness_benchmark_smoke(capsys, load_example):
    out = load_example("bench_hb_robust").main(["--smoke"])
    text = capsys.readouterr().out
    assert "Table 1" in text and "Table 2" in text
    assert not out["failures"] and all(row[1] for row in out["cost"])


def test_soft_baseline_benchmark_smoke(capsys, load_example):
    """examples/bench_hb_soft_baseline.py (the soft-contact cost baseline, runnable against
    any version of harmonic_balance): one soft row, 3.1-3.2 evaluations per point on the
    older code, 3.7 with the steps sized by the curve's shape, which takes 76 points
    instead of 393 (at least 1 / frf.LAM_STEP)."""
    from harmonic_balance.frf import LAM_STEP

    rows = load_example("bench_hb_soft_baseline").main(["1"])
    assert "ms/pt" in capsys.readouterr().out
    (kt, n_t, points, evals, seconds, ms), = rows
    assert kt == 1.0 and n_t == 512 and points >= 1 / LAM_STEP and 2.5 < evals < 4.0 and seconds > 0


def test_hb_against_den_hartog_table_smoke(load_example):
    """Table 4's function on one small case: 1e3 k, H = 7, at resonance, where the
    elastic model and the rigid one agree (README.md at revision c58d443: 1.1e-4 at H = 21)."""
    (kt, H, errs), = load_example("bench_hb_robust").hb_vs_den_hartog((1e3,), (7,), (1.0,))
    assert kt == 1e3 and H == 7 and abs(errs[0]) < 1e-2


def test_speed_benchmark_smoke(capsys, load_example):
    """examples/bench_hb_speed.py on the soft sdof row, without its dense references:
    a complete curve with a refined interior peak (the describing-function peak of
    this oscillator, 1.008 rad/s)."""
    (row,) = load_example("bench_hb_speed").main(["sdof", "--no-ref"])
    assert "peak omega" in capsys.readouterr().out
    assert row["ok"] and row["points"] >= 30 and 1.0 < row["peak_omega"] < 1.02
