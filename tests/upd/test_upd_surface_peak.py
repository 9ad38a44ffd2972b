"""examples/upd_surface_peak.py runs (smoke) and reports a maximum of what it solved."""
import json

import numpy as np
import pytest

pytestmark = pytest.mark.slow

def test_quick_run_reports_the_largest_solved_amplitude_and_a_ring_march(tmp_path, load_example):
    out = tmp_path / "peak.json"
    ex = load_example("upd_surface_peak")
    assert ex.main(["--quick", "--cf", "600", "--ti", "--json", str(out)]) == 0
    rec = json.loads(out.read_text())
    case = rec["cases"][0]
    surf = case["surface"][0]
    amps = [a for _, a in surf["points"]]
    # the reported peak is the best point solved (in quick mode the only one)
    assert surf["peak_amplitude_h1"] == pytest.approx(max(amps), rel=1e-12)
    assert case["point_error"] == pytest.approx(
        case["point"]["peak_amplitude_h1"] / surf["peak_amplitude_h1"] - 1, rel=1e-12)
    ring = surf["ring"]["from_hb_state"]
    assert ring["periods"] == 1 and np.isfinite(ring["amplitude_h1"]) and ring["amplitude_h1"] > 0
    assert rec["revision"]
    rows = ex.table([out]).splitlines()
    assert len(rows) == 3 and rows[2].startswith("| 600 | nodes, 1 | 5 |") and "(fixed)" in rows[2]


@pytest.mark.parametrize("extra", [["--model", "condensed", "--dashpots", "bodies"], ["--at", "-5"],
                                   ["--cf-steps", "0"]])
def test_contradictory_options_are_refused_before_any_solve(extra, capsys, load_example):
    with pytest.raises(SystemExit) as exc:
        load_example("upd_surface_peak").main(["--quick"] + extra)
    err = capsys.readouterr().err
    assert exc.value.code == 2 and ("--dashpots inputs" in err or "--at must be" in err
                                    or "--cf-steps must be" in err)


def test_a_fixed_frequency_is_not_held_against_the_point_peak(tmp_path, load_example):
    """--at solves one frequency, not the surface's peak: no point-model error is reported."""
    out = tmp_path / "at.json"
    ex = load_example("upd_surface_peak")
    assert ex.main(["--quick", "--cf", "600", "--at", "470", "--json", str(out)]) == 0
    case = json.loads(out.read_text())["cases"][0]
    assert case["surface"][0]["peak_hz"] == 470.0 and not case["surface"][0]["searched"]
    assert "point_error" not in case
    row = ex.table([out]).splitlines()[2]
    assert "470.00 (fixed)" in row and row.split(" | ")[6].endswith(", -")


#: Two Newton solutions of the same equations (|R| < solve.TOL_REL CF) reached by different
#: paths in CF agree in amplitude far below this.
SAME_SOLUTION_RTOL = 1e-6


def test_the_examples_cf_path_reaches_the_solution_of_the_librarys_first_point(tmp_path, load_example):
    """--start-cf runs the library's path (load_path.cf_path, 300 N -> 120 N in 2 steps); the
    library's own start (from the open load) reaches the same solution at 400 Hz."""
    from damper.cache import Store
    from damper.upd_surface import build_surfaces
    from harmonic_balance.bladed_disk import load_path
    from harmonic_balance.bladed_disk.config import load_config
    from harmonic_balance.bladed_disk.sector import Sector
    from harmonic_balance.bladed_disk.surface_hb import CondensedSurfaceSectorHB

    out = tmp_path / "path.json"
    assert load_example("upd_surface_peak").main(["--quick", "--model", "condensed", "--cf", "120", "--start-cf", "300",
                            "--cf-steps", "2", "--at", "400", "--json", str(out)]) == 0
    amp = json.loads(out.read_text())["cases"][0]["surface"][0]["peak_amplitude_h1"]
    cfg = load_config(None)
    surfaces = build_surfaces(cfg, 5, 120.0, Store().prepare())
    sector = Sector(cfg)

    def make(c):
        return CondensedSurfaceSectorHB(sector, surfaces, 1, cf=c)
    x, rec = load_path.first_point(make, 2 * np.pi * 400.0, 120.0)
    assert rec["loads"][0] == pytest.approx(rec["open_load"]) and rec["open_load"] > 300.0
    assert amp == pytest.approx(make(120.0).amplitude_h1(x), rel=SAME_SOLUTION_RTOL)
