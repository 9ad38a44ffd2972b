"""``damper study ... --quick``: sensible exponents, thesis trends, equilibrium."""
import json

import pytest

from damper.cli import main as damper

#: Equilibrium of every eccentric case: force and moment met by the Newton
#: iteration to normal.FORCE_RTOL (1e-9); measured 1.4e-14 (force), 6.6e-15 (moment).
EQUILIBRIUM_TOL = 1e-9


@pytest.fixture(scope="module")
def cache_dir(tmp_path_factory):
    return str(tmp_path_factory.mktemp("study_cache"))


@pytest.mark.slow
def test_cylinder_study_quick_exponents(cache_dir, capsys, tmp_path):
    assert damper(["study", "cylinders", "--quick", "--json", "--cache-dir", cache_dir,
                   "--plot", str(tmp_path)]) == 0
    out = json.loads(capsys.readouterr().out)
    for law in ("normal", "tangential"):
        assert set(out[law]) >= {"C", "a", "b", "c"}
    n, t = out["normal"], out["tangential"]
    assert 0.5 < n["a"] < 1.0          # the normal F exponent is below 1 (Hertz-like stiffening)
    assert n["c"] > 0 and t["c"] > 0   # a larger diameter gives a larger approach (thesis 2.2.5)
    assert n["b"] > 0 and t["b"] > 0   # a longer cylinder is stiffer
    assert (tmp_path / "cylinders.png").is_file()
    # compression share (section 2.2.5): outside the contact, below the centre share
    for m in out["compression"]:
        for far, centre in zip(m["body1_share_far"], m["body1_share"]):
            assert far is None or 0 < far < centre
    # the sphere of the same diameter: its own compression is small (thesis Fig. 17: < 8 %)
    sphere = [v for v in out["compression_sphere"]["body1_share_far"] if v is not None]
    assert sphere and all(0 < v < 0.08 for v in sphere)


@pytest.mark.slow
def test_eccentric_study_quick_equilibrium_and_trend(cache_dir, capsys):
    assert damper(["study", "eccentric", "--quick", "--json", "--cache-dir", cache_dir]) == 0
    cases = json.loads(capsys.readouterr().out)["cases"]
    assert [c["case"] for c in cases] == [f"e{k}" for k in range(9)]
    for c in cases:
        assert c["force_residual"] < EQUILIBRIUM_TOL and c["moment_residual"] < EQUILIBRIUM_TOL
    partial = [c for c in cases if c["contact_fraction"] < 0.999]
    assert len(partial) >= 3
    areas = [c["loop_area_ratio"] for c in partial]
    assert all(a > b for a, b in zip(areas, areas[1:]))  # falls as eccentricity grows (thesis 3.3.1)
    assert cases[0]["loop_area_ratio"] == 1.0


def test_study_refuses_bad_workers(capsys):
    assert damper(["study", "eccentric", "--workers", "0"]) == 2
    assert "--workers" in capsys.readouterr().err


def test_richardson_recovers_a_power_law_limit():
    from damper.studies.convergence import richardson

    h = [1 / 6, 1 / 12, 1 / 24]
    f = [2.0 + 0.3 * x**1.7 for x in h]          # converged value 2, order 1.7
    r = richardson(f, h)
    assert r["value"] == pytest.approx(2.0, rel=1e-12) and r["order"] == pytest.approx(1.7, rel=1e-9)
    r = richardson([1.0, 1.2, 1.1], h)            # oscillating: no order, finest value kept
    assert r["order"] is None and r["value"] == 1.1 and not r["monotone"]
