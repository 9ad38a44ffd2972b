"""Smoke run of examples/bench_fmu.py with tiny settings (timings are not checked)."""
import runpy
from pathlib import Path

BENCH = Path(__file__).resolve().parents[2] / "examples" / "bench_fmu.py"
#: The C master and the array API run the same core on the same history.
EXACT_TOL = 1e-12


def test_bench_fmu_smoke(capsys):
    bench = runpy.run_path(str(BENCH), run_name="bench_fmu")
    rows = bench["measure"](n_sliders=5, steps=500, py_steps=50, repeats=1)
    extra = bench["print_table"](rows)
    out = capsys.readouterr().out
    assert "element's own cost" in out and "passthrough" in out
    assert {r["case"] for r in rows} == {"iwan", "passthrough"}
    assert all(r["error"] <= EXACT_TOL for r in rows)
    assert all(r["c_ns"] > 0 and r["fmpy_us"] > 0 for r in rows)
    assert extra == rows[1]["c_ns"] - rows[0]["c_ns"]
