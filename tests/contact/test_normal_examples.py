"""Smoke versions of the normal-contact examples (the full runs are their own commands)."""
from __future__ import annotations

import json

import numpy as np
import pytest


def test_palmgren_formula_matches_the_seed_units(load_example):
    cyl = load_example("cylinder_approach")
    # references.md: steel on steel, d[mm] = 3.84e-5 F^0.9 / L[mm]^0.8
    d = cyl.formulas(350.0, L=1.2e-3)["Palmgren/Harris"]
    assert d == pytest.approx(3.84e-5 * 350.0**0.9 / 1.2**0.8 * 1e-3, rel=1e-12)
    # every formula gives a positive approach growing with the force
    for name, v in cyl.formulas(np.array([50.0, 100.0, 400.0])).items():
        assert np.all(v > 0) and np.all(np.diff(v) > 0), name


def test_kosarev_half_width_is_hertz():
    from contact_core import hertz

    F, R, L, E, nu = 350.0, 2.5e-3, 1.2e-3, 200e9, 0.3
    lam = 2 * (1 - nu**2) / (np.pi * E)
    b = np.sqrt(4 * F * R * lam / L)
    assert b == pytest.approx(hertz.cylinder(F, L, R, hertz.contact_modulus(E, nu, E, nu))["b"], rel=1e-12)


@pytest.mark.slow
def test_bench_contact_quick_case_runs(tmp_path, monkeypatch, load_example):
    bench = load_example("bench_contact")
    assert bench.main(["--quick", "--out", str(tmp_path)]) == 0
    rows = json.loads((tmp_path / "bench_contact.json").read_text())
    # the second run loads the condensed model (what happened, not how long it took)
    assert not rows[0]["cold"]["cache_hit"] and rows[0]["cached"]["cache_hit"]


@pytest.mark.slow
def test_normal_validation_writes_json_and_plots(tmp_path, contact_cache, load_example):
    val = load_example("normal_validation")
    summary = val.main(tmp_path, cache=contact_cache)
    data = json.loads((tmp_path / "normal_validation.json").read_text())
    assert set(data) == {"sphere", "cylinder"} == set(summary)
    assert abs(data["sphere"]["hertz"]["error_size"]) < 0.02
    assert abs(data["sphere"]["approach_fit"]["error_A"]) < 0.02
    for case in ("sphere", "cylinder"):
        for png in ("pressure_map", "contact_area", "f_approach", "pressure_profiles"):
            assert (tmp_path / case / f"{png}.png").stat().st_size > 1000
