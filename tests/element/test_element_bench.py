"""Smoke test of examples/bench_element.py (tiny sizes; never gates on wall time)."""
from __future__ import annotations


def test_bench_element_runs_and_its_numbers_agree(capsys, load_example):
    bench = load_example("bench_element")
    rows = bench.run([1, 5], n_samples=300, repeats=2)
    assert [r["sliders"] for r in rows] == [1, 5]
    for r in rows:
        assert r["c_ns_sample"] > 0 and r["py_ns_sample"] > 0
        assert r["diff"] < 1e-12           # same C code on both paths: round-off only
        assert r["masing_err"] < 1e-12     # loop energy vs Masing's integral, exact for a table
    assert bench.main(["--sizes", "2", "--samples", "100", "--repeats", "1"]) == 0
    assert "ns/slider" in capsys.readouterr().out
