"""Smoke run of examples/bench_hb_robust.py (the full run is by hand)."""
import pytest

from harmonic_balance.continuation import LAM_STEP


@pytest.mark.slow  # > 1 s: outside the `-m "not slow"` inner loop
def test_robustness_benchmark_smoke(capsys, load_example):
    out = load_example("bench_hb_robust").main(["--smoke"])
    text = capsys.readouterr().out
    assert "Table 1" in text and "Table 2" in text
    assert not out["failures"] and all(row[1] for row in out["cost"])
    # Table 2's rows (kt, ok, points, iterations, seconds, evaluations, ms/eval): the
    # continuation's largest step (LAM_STEP of the band) bounds the points from below,
    # and every point costs at least one residual evaluation
    for kt, _, pts, _, _, nev, ms in out["cost"]:
        assert pts >= 1 / LAM_STEP and nev >= pts and ms > 0, kt


def test_hb_against_den_hartog_table_smoke(load_example):
    """Table 4's function on one small case: 1e3 k, H = 7, at resonance, where the
    elastic model and the rigid one agree (README.md at revision c58d443: 1.1e-4 at H = 21)."""
    (kt, H, errs), = load_example("bench_hb_robust").hb_vs_den_hartog((1e3,), (7,), (1.0,))
    assert kt == 1e3 and H == 7 and abs(errs[0]) < 1e-2
