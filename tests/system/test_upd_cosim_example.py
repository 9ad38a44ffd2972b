"""Smoke run of examples/upd_cosim.py (CF 120 N, 3 periods a frequency): the table's
columns exist and the transient matches the ring time integration."""
import pytest


@pytest.mark.slow
def test_quick_run(tmp_path, load_example):
    upd_cosim = load_example("upd_cosim")
    rows = upd_cosim.main(["--quick", "--out", str(tmp_path)])
    r = rows[0]
    assert r["cf"] == 120.0 and len(r["cosim"]) == len(upd_cosim.FACTORS)
    # the same 3 periods of the same ODE from the same prestress (measured 4e-4)
    assert max(abs(e) for e in r["cosim_vs_ti"]) < 2e-3
    assert (tmp_path / "upd_cosim_period.png").exists() and (tmp_path / "upd_cosim.json").exists()
