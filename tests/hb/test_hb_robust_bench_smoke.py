"""Smoke run of examples/bench_hb_robust.py (the full run is by hand)."""
import pytest


@pytest.mark.slow  # > 1 s: outside the `-m "not slow"` inner loop
def test_robustness_benchmark_smoke(capsys, load_example):
    out = load_example("bench_hb_robust").main(["--smoke"])
    text = capsys.readouterr().out
    assert "Table 1" in text and "Table 2" in text
    assert not out["failures"] and all(row[1] for row in out["cost"])
