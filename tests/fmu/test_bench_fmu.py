"""Smoke run of examples/bench_fmu.py with tiny settings (timings are not checked)."""
import runpy
from pathlib import Path

import pytest

BENCH = Path(__file__).resolve().parents[2] / "examples" / "bench_fmu.py"
#: The C master and the array API run the same core on the same history.
EXACT_TOL = 1e-12


@pytest.mark.slow  # > 2 s: outside the `-m "not slow"` inner loop
def test_bench_fmu_smoke(capsys):
    bench = runpy.run_path(str(BENCH), run_name="bench_fmu")
    rows = bench["measure"]([3, 50], steps=500, py_steps=50, repeats=1)
    costs = bench["print_table"](rows)
    out = capsys.readouterr().out
    assert "element's own cost" in out and "passthrough" in out
    assert [(r["case"], r["sliders"]) for r in rows] == [
        ("passthrough", 0), ("iwan", 3), ("iwan", 50)]
    assert all(r["error"] <= EXACT_TOL for r in rows)
    assert all(r["c_ns"] > 0 and r["fmpy_us"] > 0 for r in rows)
    assert costs[50] == rows[2]["c_ns"] - rows[0]["c_ns"]
