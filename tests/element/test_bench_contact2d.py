"""Smoke test of examples/bench_contact2d.py (tiny sizes; never gates on wall time)."""
from __future__ import annotations

import pytest


@pytest.mark.slow  # two FMU builds and the driver: ~10 s

def test_bench_contact2d_runs_and_its_numbers_agree(capsys, load_example):
    bench = load_example("bench_contact2d")
    rows = bench.element_rows([3], per=1000, cycles=10, repeats=1, count=False)
    assert [r["case"] for r in rows] == list(bench.CASES)
    check = {r["case"]: r["check"] for r in rows}
    assert check["line2d"] < 1e-12            # the 1D element's cycle energy, to round-off
    assert check["point"] < 1e-12             # contact point = 2D element at N(p) (penalty law)
    assert check["circle"] < 1e-4             # steady circles (the 1000-gon: ~4e-6)
    assert all(r["ns_step"] > 0 for r in rows)
    frows = bench.fmu_rows(4, steps=300, repeats=1)
    assert [r["fmu"] for r in frows] == ["1D FMU", "point FMU"] and all(r["W"] > 0 for r in frows)
    bench.print_tables(rows, frows)
    assert "ns/doStep" in capsys.readouterr().out
