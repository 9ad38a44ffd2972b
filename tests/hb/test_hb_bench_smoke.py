"""Smoke run of examples/bench_hb.py with tiny settings (the full run is by hand)."""
import pytest

#: The smoke reference uses 64/128 steps per period and a loose steady-state
#: tolerance (its own step error ~0.2 %): H = 3 must still land within 1 %.
SMOKE_RTOL = 1e-2


@pytest.mark.slow  # > 2 s: outside the `-m "not slow"` inner loop
def test_benchmark_smoke_runs_and_h3_is_close_to_the_reference(capsys, load_example):
    bench = load_example("bench_hb")
    out = bench.main(["--smoke"])
    text = capsys.readouterr().out
    assert "Table 1" in text and "Table 2" in text and "Speed-up" in text
    H, r, err = out["rows"][-1]
    assert H == 3 and abs(err) < 100 * SMOKE_RTOL and out["reference_error"] < SMOKE_RTOL
    assert out["sizes"][0][1].status == "complete"
    # Table 3a: the vectorised time integration settled on every frequency of the
    # HB curve and its peak agrees with the reference within the smoke tolerance
    name, ns, tol, t_hb, t_ti, speedup, h1_dev, peak_err, settled = out["vectorised"][0]
    assert settled and abs(peak_err) < 100 * SMOKE_RTOL and t_ti > 0 and t_hb > 0
